// The `heterskinnet` model (experiments/heterskinnet/) trained end to end through the Trainer on
// small synthetic tubes, and the shipped experiment configs validated.

#include <gtest/gtest.h>

#include <filesystem>

#include "../test_util.hpp"
#include "framework/tensors/threads.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/train/trainer.hpp"
#include "train_fixtures.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;

const fs::path& tubes() {
  static testing::TempDir dir;
  static const fs::path file = [] {
    const fs::path f = dir / "tubes.h5";
    testing::write_tube_dataset(f, 4, 1, 1);
    return f;
  }();
  return file;
}

// configs/smoke.yaml (the paper's architecture with tiny widths, what CI runs) on the tubes.
config::Config tiny_config(const fs::path& results) {
  return config::Config::load(
      std::string(SKINLAB_SOURCE_DIR) + "/configs/smoke.yaml",
      {"data.file=" + tubes().string(), "data.distance=euclidean",
       "results_dir=" + results.string(), "train.lr=1.0e-3", "train.epochs=6",
       "train.max_characters_per_epoch=0", "train.patience=0"});
}

TEST(HeterSkinNet, TrainsLossDecreasesAndPredictsValidWeights) {
  set_torch_threads(2);
  testing::TempDir results;
  const config::Config config = tiny_config(results.path());
  train::Trainer trainer(config);
  const double before = trainer.mean_loss("train");
  const RunDir run = train::create_run(config, trainer.options(), "a", {"test"});
  const train::TrainResult r = trainer.fit(run);
  EXPECT_EQ(r.epochs, 6);
  const double after = trainer.mean_loss("train");
  EXPECT_LT(after, before) << "train loss did not decrease: " << before << " → " << after;

  trainer.model().eval();
  torch::NoGradGuard no_grad;
  const auto& c = trainer.data().tensors(trainer.data().part("test").at(0));
  const torch::Tensor w = trainer.model().forward(c);
  ASSERT_EQ(w.sizes(), (std::vector<std::int64_t>{c.num_vertices(), 3}));
  EXPECT_TRUE((w >= 0).all().item<bool>());
  EXPECT_TRUE(torch::allclose(w.sum(1), torch::ones({c.num_vertices()}), 1e-5, 1e-5));
  const torch::Tensor full = data::scatter_to_bones(w, c.topk_index, c.num_bones());
  EXPECT_TRUE(((full > 0).sum(1) <= 3).all().item<bool>());
  // Eval mode is deterministic (no edge or head dropout).
  EXPECT_TRUE(torch::equal(w, trainer.model().forward(c)));
  // Without gradients b2v and the head split their first layer by weight blocks and EdgeConv
  // fuses its gather and min; with them the network runs as in training. Same weights up to
  // float rounding.
  torch::Tensor tracked;
  {
    torch::GradMode::set_enabled(true);
    tracked = trainer.model().forward(c);
    torch::GradMode::set_enabled(false);
  }
  ASSERT_TRUE(tracked.requires_grad());
  EXPECT_TRUE(torch::allclose(w, tracked.detach(), 1e-5, 1e-6));
}

// The paper-width network as initialised (Kaiming normal) must start from soft predictions: with
// 1/D in metres (up to 10³) it started with one-hot rows and the softmax never recovered.
TEST(HeterSkinNet, PaperWidthsStartUnsaturated) {
  set_torch_threads(2);
  testing::TempDir results;
  const config::Config config = config::Config::load(
      std::string(SKINLAB_SOURCE_DIR) + "/configs/heterskinnet.yaml",
      {"data.file=" + tubes().string(), "data.distance=euclidean",
       "results_dir=" + results.path().string()});
  train::Trainer trainer(config);
  trainer.model().eval();
  torch::NoGradGuard no_grad;
  const auto& c = trainer.data().tensors(trainer.data().part("train").at(0));
  const torch::Tensor top = std::get<0>(trainer.model().forward(c).max(1));
  EXPECT_LT((top > 0.99).to(torch::kFloat).mean().item<float>(), 0.05)
      << "most rows start one-hot; mean largest weight " << top.mean().item<float>();
}

TEST(HeterSkinNet, BadOptionsAreConfigErrors) {
  auto make = [](const std::string& yaml) {
    return model_registry().create(config::Config::parse(yaml, "m.yaml").root());
  };
  EXPECT_THROW(make("type: heterskinnet\nhead_widths: [8]"), ConfigError);
  EXPECT_THROW(make("type: heterskinnet\nhead_dropout: 1.5"), ConfigError);
  EXPECT_THROW(make("type: heterskinnet\ndistance_unit: 0"), ConfigError);
  EXPECT_THROW(make("type: heterskinnet\nmin_distance: -1"), ConfigError);
  EXPECT_THROW(make("type: heterskinnet\nlocal: [{type: edge_cnv}]"), Error);
  EXPECT_THROW(make("type: heterskinnet\nedge_dropout: {p: 2}"), ConfigError);
}

TEST(HeterSkinNet, ShippedExperimentConfigsValidate) {
  for (const char* file :
       {"heterskinnet.yaml", "heterskinnet_bundled.yaml", "smoke.yaml", "ablations/euclidean.yaml",
        "ablations/no_heterconv.yaml", "ablations/no_smoothing.yaml"}) {
    const auto config = config::Config::load(std::string(SKINLAB_SOURCE_DIR) + "/configs/" + file);
    const auto options = train::RunOptions::from(config);
    EXPECT_NO_THROW(options.require_training_sections(config)) << file;
    EXPECT_NO_THROW(model_registry().create(options.model)) << file;
  }
  for (const char* file : {"baselines/geo_voxel.yaml", "baselines/bone_heat.yaml"}) {
    const auto config = config::Config::load(std::string(SKINLAB_SOURCE_DIR) + "/configs/" + file);
    const auto options = train::RunOptions::from(config);
    EXPECT_NO_THROW(options.require_binder_sections(config)) << file;
    EXPECT_THROW(options.require_training_sections(config), ConfigError) << file;
  }
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

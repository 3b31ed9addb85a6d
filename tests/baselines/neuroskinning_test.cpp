// NeuroSkinning's network (baselines/neuroskinning): the widths of its Fig. 3, the input
// composition (position, outward normal, 1/D of the Euclidean candidates), valid softmax rows,
// gradients to every parameter, an unsaturated start, a short training run on synthetic tubes,
// and the shipped config.

#include "baselines/neuroskinning/neuroskinning.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>

#include "framework/tensors/threads.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/train/run_options.hpp"
#include "framework/train/trainer.hpp"
#include "tests/baselines/model_fixtures.hpp"
#include "tests/test_util.hpp"
#include "tests/train/train_fixtures.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using baselines::NeuroSkinning;

constexpr const char* kTiny =
    "{type: neuroskinning, top_k: 3, input_mlp: [8],"
    " stem: [{type: gconv_pool, mlp: [8]}],"
    " local: [{type: gconv_pool, mlp: [4]}, {type: gconv_pool, mlp: [4]}],"
    " global: {type: global_pool, pool: [vertex], vertex_mlp: [16], to: [vertex],"
    " keep_input: false}, head: [16]}";

std::shared_ptr<NeuroSkinning> make(const std::string& yaml) {
  return testing::make_model<NeuroSkinning>(yaml);
}

const data::CharacterTensors& tube(int index) { return testing::tube_tensors(index); }

using testing::expect_valid_rows;

TEST(NeuroSkinning, DefaultsAreTheFiguresWidths) {
  const auto m = make("type: neuroskinning");
  EXPECT_EQ(m->options().top_k, 3);
  EXPECT_TRUE(m->options().normals);
  const auto p = m->named_parameters();
  // 6 + K → 64; GCU 64 → 64 + 2·256 = 576; global 576 → 1024; GCUs 576 → 832 → 1088;
  // head 1088 + 1024 → 512 → 256 → K.
  EXPECT_EQ(p["input.linear0.weight"].sizes(), (std::vector<std::int64_t>{64, 9}));
  EXPECT_EQ(p["stem.0_gconv_pool.mlp.linear0.weight"].sizes(),
            (std::vector<std::int64_t>{256, 64}));
  EXPECT_EQ(p["global_branch.vertex_mlp.linear0.weight"].sizes(),
            (std::vector<std::int64_t>{1024, 576}));
  EXPECT_EQ(p["local.0_gconv_pool.mlp.linear0.weight"].sizes(),
            (std::vector<std::int64_t>{128, 576}));
  EXPECT_EQ(p["local.1_gconv_pool.mlp.linear0.weight"].sizes(),
            (std::vector<std::int64_t>{128, 832}));
  EXPECT_EQ(p["head.linear0.weight"].sizes(), (std::vector<std::int64_t>{512, 2112}));
  EXPECT_EQ(p["head.linear2.weight"].sizes(), (std::vector<std::int64_t>{3, 256}));
}

TEST(NeuroSkinning, InputIsPositionNormalAndInverseDistances) {
  const auto& c = tube(0);
  const auto m = make("{type: neuroskinning, distance_unit: 0.01, min_distance: 2}");
  const torch::Tensor f = m->input_features(c);
  ASSERT_EQ(f.sizes(), (std::vector<std::int64_t>{c.num_vertices(), 6 + 3}));
  EXPECT_TRUE(torch::equal(f.slice(1, 0, 3), c.positions));
  EXPECT_TRUE(torch::equal(f.slice(1, 3, 6), c.normals));
  const torch::Tensor expected = 1.0 / (c.topk_distance / 0.01).clamp_min(2.0);
  EXPECT_TRUE(torch::allclose(f.slice(1, 6), expected));
  // The tube is a closed-ish surface around its axis: outward normals point away from it
  // (positive radial component for most vertices).
  const torch::Tensor radial = c.positions.index({torch::indexing::Slice(), torch::tensor({0, 2})});
  const torch::Tensor centre = radial.mean(0, true);
  const torch::Tensor outward =
      ((radial - centre) * c.normals.index({torch::indexing::Slice(), torch::tensor({0, 2})}))
          .sum(1);
  EXPECT_GT((outward > 0).to(torch::kFloat).mean().item<float>(), 0.5);
  EXPECT_EQ(make("{type: neuroskinning, normals: false}")->input_features(c).size(1), 3 + 3);
  data::CharacterTensors no_normals = c;
  no_normals.normals = torch::Tensor();
  testing::expect_error<c10::Error>([&] { m->input_features(no_normals); },
                                    {"neuroskinning", "normals"});
}

TEST(NeuroSkinning, ForwardAndGradients) {
  torch::manual_seed(0);
  const auto m = make(kTiny);
  m->train();
  const auto& c = tube(1);
  const torch::Tensor w = m->forward(c);
  expect_valid_rows(w, c);
  (-(c.targets * torch::log(w.clamp_min(1e-8))).sum(1).mean()).backward();
  for (const auto& p : m->named_parameters()) {
    ASSERT_TRUE(p.value().grad().defined()) << p.key();
    EXPECT_GT(p.value().grad().abs().max().item<float>(), 0.0f) << p.key();
  }
  m->eval();
  torch::NoGradGuard no_grad;
  expect_valid_rows(m->forward(tube(2)), tube(2));
  EXPECT_TRUE(torch::equal(m->forward(c), m->forward(c)));
}

TEST(NeuroSkinning, PaperWidthsStartUnsaturated) {
  torch::manual_seed(0);
  const auto m = make("type: neuroskinning");
  m->eval();
  torch::NoGradGuard no_grad;
  const torch::Tensor top = std::get<0>(m->forward(tube(3)).max(1));
  EXPECT_LT((top > 0.99).to(torch::kFloat).mean().item<float>(), 0.05)
      << "mean largest weight " << top.mean().item<float>();
}

TEST(NeuroSkinning, ACharacterWithFewerBonesThanKGetsWeightsOnItsOwnBones) {
  std::string yaml = kTiny;
  yaml.replace(yaml.find("top_k: 3"), 8, "top_k: 8");
  testing::expect_own_candidates_below_k(*make(yaml), 8);
}

TEST(NeuroSkinning, OptionErrorsNameTheField) {
  using testing::expect_error;
  expect_error<ConfigError>([] { make("{type: neuroskinning, input_mlp: [0]}"); }, {"input_mlp"});
  expect_error<ConfigError>([] { make("{type: neuroskinning, normal: true}"); }, {"normal"});
  expect_error<ConfigError>([] { make("{type: neuroskinning, top_k: 0}"); }, {"top_k"});
  const auto m = make("{type: neuroskinning, top_k: 2}");
  expect_error<c10::Error>([&] { m->forward(tube(0)); }, {"neuroskinning", "top_k = 2"});
}

TEST(NeuroSkinning, TrainingOnTubesLowersTheLoss) {
  set_torch_threads(2);
  testing::TempDir dir;
  const fs::path data = dir / "tubes.h5";
  testing::write_tube_dataset(data, 4, 1, 1);
  const std::string yaml = std::string("experiment: neuro_tubes\nseed: 3\nresults_dir: ") +
                           (dir / "results").string() + "\nmodel: " + kTiny +
                           "\nlosses: [{type: kl, weight: 1.0}]\n"
                           "data: {file: " +
                           data.string() +
                           ", split: random, distance: euclidean}\n"
                           "train: {epochs: 6, lr: 1.0e-3, weight_decay: 1.0e-4, patience: 0,"
                           " log_every: 0}\n";
  const config::Config config = config::Config::parse(yaml, "tubes.yaml");
  train::Trainer trainer(config);
  const double before = trainer.mean_loss("train");
  const RunDir run = train::create_run(config, trainer.options(), "a", {"test"});
  EXPECT_EQ(trainer.fit(run).epochs, 6);
  const double after = trainer.mean_loss("train");
  EXPECT_LT(after, before) << "train loss did not decrease: " << before << " → " << after;
}

TEST(NeuroSkinning, ShippedConfigValidates) {
  const auto config = config::Config::load(std::string(SKINLAB_SOURCE_DIR) +
                                           "/configs/baselines/neuroskinning.yaml");
  const auto options = train::RunOptions::from(config);
  EXPECT_NO_THROW(options.require_training_sections(config));
  EXPECT_NO_THROW(model_registry().create(options.model));
  EXPECT_EQ(config.root()["data"]["distance"].as<std::string>(), "euclidean");
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

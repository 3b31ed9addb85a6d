// RigNet's skinning network (baselines/rignet_skin): input composition, valid softmax rows,
// gradients to every parameter, an unsaturated start at RigNet's widths, deterministic eval,
// option errors, a short training run on synthetic tubes, and the shipped config.

#include "baselines/rignet_skin/rignet_skin.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

#include "framework/tensors/threads.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/losses/loss.hpp"
#include "framework/train/run_options.hpp"
#include "framework/train/trainer.hpp"
#include "tests/baselines/model_fixtures.hpp"
#include "tests/test_util.hpp"
#include "tests/train/train_fixtures.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using baselines::RigNetSkin;

// Small widths for the tests that train or differentiate; RigNet's own widths are the defaults.
constexpr const char* kTiny =
    "type: rignet_skin\n"
    "top_k: 3\n"
    "input_mlp: [16, 8]\n"
    "stem: [{type: mesh_conv, edge_mlp: [8, 8], mlp: [16]}]\n"
    "local: [{type: mesh_conv, edge_mlp: [8, 8], mlp: [16]},"
    " {type: mesh_conv, edge_mlp: [8, 8], mlp: [16]}]\n"
    "global: {type: global_pool, pool: [vertex], vertex_mlp: [16, 32], to: [vertex],"
    " keep_input: false}\n"
    "head: [32, 16]\n";

std::shared_ptr<RigNetSkin> make(const std::string& yaml) {
  return testing::make_model<RigNetSkin>(yaml);
}

const data::CharacterTensors& tube(int index) { return testing::tube_tensors(index); }

const fs::path& tubes() {
  static testing::TempDir dir;
  static const fs::path file = [] {
    const fs::path f = dir / "tubes.h5";
    testing::write_tube_dataset(f, 4, 1, 1);
    return f;
  }();
  return file;
}

using testing::expect_valid_rows;

TEST(RigNetSkin, DefaultsAreRigNetsWidths) {
  const auto m = make("type: rignet_skin");
  EXPECT_EQ(m->options().top_k, 3);
  EXPECT_TRUE(m->options().leaf_flag);
  EXPECT_EQ(m->options().input_mlp, (std::vector<std::int64_t>{128, 64}));
  EXPECT_EQ(m->options().head, (std::vector<std::int64_t>{1024, 512}));
  EXPECT_DOUBLE_EQ(m->options().head_dropout, 0.0);
  const auto params = m->named_parameters();
  // input MLP 3 + 8K → 128 → 64; GCU1 edge MLPs 2·64 → 256 → 256, fusion 512 → 512; global
  // 512 → 512 → 1024; GCU2/3 edge MLPs 2·512 (2·256) → 128 → 128, fusion 256 → 256; head
  // 256 + 1024 → 1024 → 512 → K.
  EXPECT_EQ(params["input.linear0.weight"].sizes(), (std::vector<std::int64_t>{128, 27}));
  EXPECT_EQ(params["input.linear1.weight"].sizes(), (std::vector<std::int64_t>{64, 128}));
  EXPECT_EQ(params["stem.0_mesh_conv.edge_mlp_one_ring.linear0.weight"].sizes(),
            (std::vector<std::int64_t>{256, 128}));
  EXPECT_EQ(params["stem.0_mesh_conv.edge_mlp_geodesic.linear1.weight"].sizes(),
            (std::vector<std::int64_t>{256, 256}));
  EXPECT_EQ(params["stem.0_mesh_conv.mlp.linear0.weight"].sizes(),
            (std::vector<std::int64_t>{512, 512}));
  EXPECT_EQ(params["global_branch.vertex_mlp.linear1.weight"].sizes(),
            (std::vector<std::int64_t>{1024, 512}));
  EXPECT_EQ(params["local.0_mesh_conv.edge_mlp_one_ring.linear0.weight"].sizes(),
            (std::vector<std::int64_t>{128, 1024}));
  EXPECT_EQ(params["local.1_mesh_conv.mlp.linear0.weight"].sizes(),
            (std::vector<std::int64_t>{256, 256}));
  EXPECT_EQ(params["head.linear0.weight"].sizes(), (std::vector<std::int64_t>{1024, 1280}));
  EXPECT_EQ(params["head.linear2.weight"].sizes(), (std::vector<std::int64_t>{3, 512}));
}

// f_v = p ‖ [start, end, 1/D, leaf] per candidate, nearest first, D in units clamped at one.
TEST(RigNetSkin, InputFeaturesFollowRigNetsLayout) {
  const auto& c = tube(0);
  const auto m = make("type: rignet_skin\ndistance_unit: 0.01\nmin_distance: 2");
  const torch::Tensor f = m->input_features(c);
  ASSERT_EQ(f.sizes(), (std::vector<std::int64_t>{c.num_vertices(), 3 + 8 * 3}));
  for (std::int64_t v : {std::int64_t{0}, c.num_vertices() / 2, c.num_vertices() - 1}) {
    EXPECT_TRUE(torch::equal(f[v].slice(0, 0, 3), c.positions[v]));
    for (std::int64_t k = 0; k < 3; ++k) {
      const std::int64_t b = c.topk_index[v][k].item<std::int64_t>();
      const torch::Tensor rec = f[v].slice(0, 3 + 8 * k, 3 + 8 * (k + 1));
      EXPECT_TRUE(torch::equal(rec.slice(0, 0, 6), c.bones[b]));
      const double d = c.topk_distance[v][k].item<float>();
      EXPECT_NEAR(rec[6].item<float>(), 1.0 / std::max(d / 0.01, 2.0), 1e-5);
      const bool leaf =
          c.bone_joints[b][0].item<std::int64_t>() == c.bone_joints[b][1].item<std::int64_t>();
      EXPECT_EQ(rec[7].item<float>(), leaf ? 1.0f : 0.0f);
    }
  }
  // Some candidate is a leaf bone and some is not (the tubes' head and arm have helper bones).
  const torch::Tensor leaf_cols = f.slice(1, 3).reshape({c.num_vertices(), 3, 8}).select(2, 7);
  EXPECT_TRUE((leaf_cols == 1).any().item<bool>());
  EXPECT_TRUE((leaf_cols == 0).any().item<bool>());
  const auto no_leaf = make("type: rignet_skin\nleaf_flag: false");
  EXPECT_EQ(no_leaf->input_features(c).size(1), 3 + 7 * 3);
  EXPECT_NO_THROW(expect_valid_rows(no_leaf->forward(c), c));
}

TEST(RigNetSkin, ForwardGivesADistributionOverTheCandidates) {
  torch::manual_seed(0);
  const auto m = make(kTiny);
  for (int i : {0, 1, 2}) {
    const auto& c = tube(i);
    m->train();
    expect_valid_rows(m->forward(c), c);
    m->eval();
    torch::NoGradGuard no_grad;
    expect_valid_rows(m->forward(c), c);
  }
}

TEST(RigNetSkin, GradientsReachEveryParameter) {
  torch::manual_seed(1);
  const auto m = make(kTiny);
  m->train();
  const auto& c = tube(1);
  const torch::Tensor w = m->forward(c);
  const torch::Tensor loss = -(c.targets * torch::log(w.clamp_min(1e-8))).sum(1).mean();
  loss.backward();
  for (const auto& p : m->named_parameters()) {
    ASSERT_TRUE(p.value().grad().defined()) << p.key();
    EXPECT_TRUE(torch::isfinite(p.value().grad()).all().item<bool>()) << p.key();
    EXPECT_GT(p.value().grad().abs().max().item<float>(), 0.0f) << p.key();
  }
  EXPECT_GT(m->parameters().size(), 20u);
}

// RigNet's widths as initialised must start from soft predictions (1/D in metres would give
// inputs up to 10⁸ here and one-hot rows; HeterSkinNet's lesson, heterskinnet.hpp).
TEST(RigNetSkin, PaperWidthsStartUnsaturated) {
  torch::manual_seed(0);
  const auto m = make("type: rignet_skin");
  m->eval();
  torch::NoGradGuard no_grad;
  for (int i : {0, 3}) {
    const auto& c = tube(i);
    const torch::Tensor w = m->forward(c);
    expect_valid_rows(w, c);
    const torch::Tensor top = std::get<0>(w.max(1));
    const float saturated = (top > 0.99).to(torch::kFloat).mean().item<float>();
    EXPECT_LT(saturated, 0.05) << "most rows start one-hot; mean largest weight "
                               << top.mean().item<float>();
    std::cout << c.name << ": rows with max > 0.99: " << saturated << ", mean largest weight "
              << top.mean().item<float>() << "\n";
  }
}

TEST(RigNetSkin, EvalIsDeterministicAndDropoutOnlyTrains) {
  torch::manual_seed(2);
  const auto m = make(std::string(kTiny) + "head_dropout: 0.5\n");
  const auto& c = tube(2);
  m->eval();
  torch::NoGradGuard no_grad;
  const torch::Tensor a = m->forward(c);
  EXPECT_TRUE(torch::equal(a, m->forward(c)));
  m->train();
  EXPECT_FALSE(torch::equal(a, m->forward(c)));
  m->eval();
  EXPECT_TRUE(torch::equal(a, m->forward(c)));
}

TEST(RigNetSkin, RejectsAMismatchedTopK) {
  const auto m = make("type: rignet_skin\ntop_k: 2");
  testing::expect_error<c10::Error>([&] { m->forward(tube(0)); }, {"top_k = 2"});
}

TEST(RigNetSkin, ACharacterWithFewerBonesThanKGetsWeightsOnItsOwnBones) {
  std::string yaml = kTiny;
  yaml.replace(yaml.find("top_k: 3"), 8, "top_k: 8");
  testing::expect_own_candidates_below_k(*make(yaml), 8);
}

TEST(RigNetSkin, BadOptionsAreConfigErrorsNamingTheField) {
  using testing::expect_error;
  expect_error<ConfigError>([] { make("type: rignet_skin\nhead_widths: [8]"); }, {"head_widths"});
  expect_error<ConfigError>([] { make("type: rignet_skin\nhead_dropout: 1.5"); }, {"head_dropout"});
  expect_error<ConfigError>([] { make("type: rignet_skin\ndistance_unit: 0"); }, {"distance_unit"});
  expect_error<ConfigError>([] { make("type: rignet_skin\nmin_distance: -1"); }, {"min_distance"});
  expect_error<ConfigError>([] { make("type: rignet_skin\ntop_k: 0"); }, {"top_k"});
  expect_error<ConfigError>([] { make("type: rignet_skin\ninput_mlp: [0]"); }, {"input_mlp"});
  expect_error<ConfigError>([] { make("type: rignet_skin\nhead: [16, -1]"); }, {"head"});
  EXPECT_THROW(make("type: rignet_skin\nlocal: [{type: mesh_cnv}]"), Error);
}

TEST(RigNetSkin, TrainingOnTubesLowersTheLoss) {
  set_torch_threads(2);
  testing::TempDir results;
  const std::string yaml =
      "experiment: rignet_tubes\n"
      "seed: 3\n"
      "results_dir: " +
      results.path().string() +
      "\n"
      "model:\n" +
      [] {
        std::string indented;
        std::string line;
        std::istringstream in(kTiny);
        while (std::getline(in, line)) indented += "  " + line + "\n";
        return indented;
      }() +
      "losses: [{type: soft_cross_entropy, weight: 1.0}]\n"
      "data: {file: " +
      tubes().string() +
      ", split: random, distance: euclidean}\n"
      "train: {epochs: 6, lr: 1.0e-3, weight_decay: 1.0e-4, patience: 0, log_every: 0}\n";
  const config::Config config = config::Config::parse(yaml, "tubes.yaml");
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
  expect_valid_rows(trainer.model().forward(c), c);
}

TEST(RigNetSkin, ShippedConfigValidates) {
  const auto config =
      config::Config::load(std::string(SKINLAB_SOURCE_DIR) + "/configs/baselines/rignet_skin.yaml");
  const auto options = train::RunOptions::from(config);
  EXPECT_NO_THROW(options.require_training_sections(config));
  EXPECT_NO_THROW(model_registry().create(options.model));
  EXPECT_EQ(config.root()["data"]["distance"].as<std::string>(), "volumetric_geodesic");
  EXPECT_EQ(config.root()["model"]["type"].as<std::string>(), "rignet_skin");
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

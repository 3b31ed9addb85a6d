// The mesh-sequence task (experiments/bdlstm/sequence_task.hpp) on the bundled real wolf and its
// game clips: training windows never reach into a held-out window, training lowers the loss
// and an interrupted run resumes to the same parameters as an uninterrupted one.
#include "experiments/bdlstm/sequence_task.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "framework/core/run_dir.hpp"
#include "framework/train/run_options.hpp"
#include "tests/bundled_dataset.hpp"
#include "tests/test_util.hpp"

namespace skinlab::bdlstm {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

class SequenceTaskTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new skinlab::testing::TempDir();
    file_ = (*dir_ / "sequences.h5").string();
    skinlab::testing::prepare_bundled("configs/datasets/zeroad_sequences_bundled.yaml", file_);
  }
  static void TearDownTestSuite() { delete dir_; }
  static config::Config smoke(const skinlab::testing::TempDir& dir, std::vector<std::string> extra = {}) {
    std::vector<std::string> overrides = {"data.file=" + file_, "results_dir=" + dir.path().string()};
    overrides.insert(overrides.end(), extra.begin(), extra.end());
    return config::Config::load(std::string(SKINLAB_SOURCE_DIR) + "/configs/bdlstm/smoke.yaml", overrides);
  }
  static inline skinlab::testing::TempDir* dir_ = nullptr;
  static inline std::string file_;
};

std::vector<torch::Tensor> parameters_of(torch::nn::Module& m) {
  std::vector<torch::Tensor> out;
  for (const auto& p : m.parameters()) out.push_back(p.detach().clone());
  return out;
}

TEST_F(SequenceTaskTest, TrainingWindowsAvoidTheHeldOutFrames) {
  skinlab::testing::TempDir dir;
  const config::Config config = smoke(dir);
  SequenceTrainer trainer(config);
  train::RunData run_data(SequenceConfig::from(config).run.data);
  const SequenceData data(run_data.dataset(), file_, SequenceConfig::from(config).sequences.data);
  const auto& sequences = data.characters().front().sequences;
  ASSERT_FALSE(trainer.windows().empty());
  EXPECT_EQ(trainer.window_length(), 8);
  for (const auto& [s, a] : trainer.windows()) {
    const MeshSequence& q = sequences[static_cast<std::size_t>(s)];
    const int b = a + trainer.window_length();
    EXPECT_LE(b, q.num_frames());
    EXPECT_TRUE(b <= q.test_begin || a >= q.test_end) << q.clip << " " << a;
  }
}

TEST_F(SequenceTaskTest, TrainingLowersTheLossAndResumesToTheSameParameters) {
  skinlab::testing::TempDir dir;
  const config::Config config = smoke(dir, {"train.epochs=4", "train.lr=3.0e-3"});
  const auto options = train::RunOptions::from(config);
  SequenceTrainer whole(config);
  const RunDir a = train::create_run(config, options, "whole", {});
  EXPECT_EQ(whole.fit(a).epochs, 4);
  const auto metrics = a.read_metrics();
  ASSERT_EQ(metrics.size(), 4u);
  EXPECT_LT(metrics.back()["train_loss"].get<double>(), metrics.front()["train_loss"].get<double>());

  const RunDir b = train::create_run(config, options, "resumed", {});
  {
    SequenceTrainer first(config);
    train::FitLimits stop;
    stop.stop_after_epochs = 2;
    EXPECT_TRUE(first.fit(b, stop).interrupted);
  }
  SequenceTrainer second(config);
  const train::TrainResult resumed = second.fit(b);
  EXPECT_TRUE(resumed.resumed);
  EXPECT_EQ(resumed.epochs_this_call, 2);
  const auto p = parameters_of(whole.network()), q = parameters_of(second.network());
  ASSERT_EQ(p.size(), q.size());
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_TRUE(p[i].equal(q[i])) << "parameter " << i;
}

// The mesh VAE of Table 1's [4] row trains on the same windows and lowers its loss; its
// evaluation scores latent extrapolation from 2 initial frames on the held-out windows.
TEST_F(SequenceTaskTest, MeshVaeTrainsAndIsScoredOnTwoInitialFrames) {
  skinlab::testing::TempDir dir;
  const config::Config config = smoke(dir, {"model={type: mesh_vae, conv: [9, 9], latent: 16}",
                                            "train.epochs=3", "train.lr=3.0e-3",
                                            "sequences.horizons=[1, 5]"});
  const auto options = train::RunOptions::from(config);
  SequenceTrainer trainer(config);
  EXPECT_THROW(trainer.network(), Error);
  const RunDir run = train::create_run(config, options, "vae", {});
  trainer.fit(run);
  const auto metrics = run.read_metrics();
  ASSERT_EQ(metrics.size(), 3u);
  EXPECT_LT(metrics.back()["train_loss"].get<double>(), metrics.front()["train_loss"].get<double>());
  EXPECT_EQ(metrics.back()["train_parts"].count("bidir"), 0u);
  eval::EvalOptions eval_options;
  const eval::EvalReport report = evaluate_sequence(run, eval_options);
  EXPECT_GT(report.mean.at("e5_2if_mm"), 0);
  EXPECT_GT(report.mean.at("starts5"), 0);
  EXPECT_EQ(report.mean.count("e5_1if_mm"), 0u);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::bdlstm

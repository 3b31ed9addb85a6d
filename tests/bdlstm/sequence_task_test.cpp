// The mesh-sequence task (experiments/bdlstm/sequence_task.hpp) on the bundled real wolf and its
// game clips: training windows never reach into a test or validation window, training lowers
// the loss, best.pt is the epoch of lowest validation loss (the train loss without validation),
// patience stops training, and an interrupted run resumes to the same parameters as an
// uninterrupted one.
#include "experiments/bdlstm/sequence_task.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "framework/core/error.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/train/checkpoint.hpp"
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
  /// SequenceConfig::from fails on `override` with a ConfigError naming `where` (the override,
  /// or the file that sets the key), sequences.val_fraction and `says`.
  static void expect_error_in_config(const skinlab::testing::TempDir& dir, const std::string& override,
                                     const std::string& where, const std::string& says) {
    skinlab::testing::expect_error<ConfigError>([&] { SequenceConfig::from(smoke(dir, {override})); },
                                                {where, "sequences.val_fraction", says});
  }
  static inline skinlab::testing::TempDir* dir_ = nullptr;
  static inline std::string file_;
};

std::vector<torch::Tensor> parameters_of(torch::nn::Module& m) {
  std::vector<torch::Tensor> out;
  for (const auto& p : m.parameters()) out.push_back(p.detach().clone());
  return out;
}

/// The epoch (1-based) of the first lowest value of `key` in metrics.jsonl records.
std::int64_t argmin_epoch(const std::vector<nlohmann::json>& metrics, const std::string& key) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < metrics.size(); ++i) {
    if (metrics[i][key].get<double>() < metrics[best][key].get<double>()) best = i;
  }
  return metrics[best]["epoch"].get<std::int64_t>();
}

TEST_F(SequenceTaskTest, TrainingWindowsAvoidTheHeldOutFrames) {
  skinlab::testing::TempDir dir;
  for (const char* val_fraction : {"0.1", "0"}) {
    const config::Config config = smoke(dir, {std::string("sequences.val_fraction=") + val_fraction});
    SequenceTrainer trainer(config);
    train::RunData run_data(SequenceConfig::from(config).run.data);
    const SequenceData data(run_data.dataset(), file_, SequenceConfig::from(config).sequences.data);
    const auto& sequences = data.characters().front().sequences;
    ASSERT_FALSE(trainer.windows().empty());
    EXPECT_EQ(trainer.window_length(), 8);
    std::set<std::pair<int, int>> windows(trainer.windows().begin(), trainer.windows().end());
    for (std::size_t s = 0; s < sequences.size(); ++s) {
      const MeshSequence& q = sequences[s];
      const auto [held_begin, held_end] = q.held_out();
      for (int a = 0; a + trainer.window_length() <= q.num_frames(); ++a) {
        const int b = a + trainer.window_length();
        const bool clear_of_test = b <= q.test_begin || a >= q.test_end;
        const bool clear_of_val = b <= q.val_begin || a >= q.val_end;
        // Every window of training frames is drawn from, and no other.
        EXPECT_EQ(windows.count({static_cast<int>(s), a}) == 1, clear_of_test && clear_of_val)
            << q.clip << " " << a << " val_fraction " << val_fraction;
        EXPECT_EQ(clear_of_test && clear_of_val, b <= held_begin || a >= held_end);
      }
    }
    // The validation loss is computed on the validation windows: not on test or training frames.
    if (std::string(val_fraction) == "0") {
      EXPECT_FALSE(trainer.has_validation());
      EXPECT_TRUE(std::isnan(trainer.validation_loss()));
      continue;
    }
    ASSERT_TRUE(trainer.has_validation());
    std::size_t of_two_or_more = 0;
    for (const MeshSequence& q : sequences) of_two_or_more += q.val_end - q.val_begin >= 2;
    EXPECT_EQ(trainer.validation_windows().size(), of_two_or_more);
    for (const SequenceTrainer::Span& v : trainer.validation_windows()) {
      const MeshSequence& q = sequences[static_cast<std::size_t>(v.sequence)];
      EXPECT_EQ(v.begin, q.val_begin);
      EXPECT_EQ(v.end, q.val_end);
      EXPECT_TRUE(v.end <= q.test_begin || v.begin >= q.test_end) << q.clip;
    }
  }
}

// With validation windows best.pt is the epoch of lowest validation loss, the loss is a
// deterministic function of the weights (recomputed from best.pt it is the logged value), and
// train.patience stops training after that many epochs without improvement.
TEST_F(SequenceTaskTest, ValidationLossSelectsBestAndStopsEarly) {
  skinlab::testing::TempDir dir;
  const config::Config config = smoke(dir, {"train.epochs=5", "train.lr=3.0e-3"});
  const auto options = train::RunOptions::from(config);
  SequenceTrainer trainer(config);
  ASSERT_TRUE(trainer.has_validation());
  const RunDir run = train::create_run(config, options, "val", {});
  const train::TrainResult result = trainer.fit(run);
  EXPECT_EQ(result.epochs, 5);
  const auto metrics = run.read_metrics();
  ASSERT_EQ(metrics.size(), 5u);
  for (const auto& m : metrics) {
    ASSERT_TRUE(m["val_loss"].is_number()) << m.dump();
    EXPECT_TRUE(std::isfinite(m["val_loss"].get<double>()));
    EXPECT_GT(m["val_loss"].get<double>(), 0);
    for (const char* part : {"recon", "bidir", "kl", "l2"}) EXPECT_EQ(m["val_parts"].count(part), 1u) << part;
    // Selection is on the reconstruction term alone.
    EXPECT_EQ(m["val_loss"].get<double>(), m["val_parts"]["recon"].get<double>()) << m.dump();
  }
  const std::int64_t best = argmin_epoch(metrics, "val_loss");
  EXPECT_EQ(metrics.back()["best_epoch"].get<std::int64_t>(), best);
  EXPECT_EQ(result.best_epoch, best);
  const double best_val = metrics[static_cast<std::size_t>(best - 1)]["val_loss"].get<double>();
  EXPECT_EQ(result.best_loss, best_val);
  // The saved best.pt is that epoch; its validation loss, computed afresh, is the logged one.
  SequenceTrainer fresh(config);
  EXPECT_EQ(train::load_checkpoint(run.file(train::kBestCheckpoint), fresh.model()).epoch, best);
  EXPECT_NEAR(fresh.validation_loss(), best_val, 1e-6 * best_val);
  EXPECT_TRUE(fresh.model().is_training());  // the mode is restored

  // Patience: with an improvement threshold nothing meets, only epoch 1 counts as best and
  // training stops `patience` epochs later.
  skinlab::testing::TempDir patient_dir;
  const config::Config patient =
      smoke(patient_dir, {"train.epochs=10", "train.patience=2", "train.min_delta=1.0e9"});
  SequenceTrainer stopping(patient);
  const RunDir stopped = train::create_run(patient, train::RunOptions::from(patient), "patience", {});
  const train::TrainResult r = stopping.fit(stopped);
  EXPECT_TRUE(r.early_stopped);
  EXPECT_EQ(r.epochs, 3);
  EXPECT_EQ(r.best_epoch, 1);
  const auto rows = stopped.read_metrics();
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(r.best_loss, rows[0]["val_loss"].get<double>());
}

// val_fraction 0 is the paper's setting and today's behaviour: no validation loss, best.pt on
// the training loss.
TEST_F(SequenceTaskTest, WithoutValidationBestFollowsTheTrainLoss) {
  skinlab::testing::TempDir dir;
  const config::Config config = smoke(dir, {"train.epochs=3", "train.lr=3.0e-3", "sequences.val_fraction=0"});
  SequenceTrainer trainer(config);
  EXPECT_FALSE(trainer.has_validation());
  const RunDir run = train::create_run(config, train::RunOptions::from(config), "noval", {});
  const train::TrainResult result = trainer.fit(run);
  const auto metrics = run.read_metrics();
  ASSERT_EQ(metrics.size(), 3u);
  for (const auto& m : metrics) EXPECT_TRUE(m["val_loss"].is_null()) << m.dump();
  EXPECT_EQ(result.best_epoch, argmin_epoch(metrics, "train_loss"));
  EXPECT_EQ(metrics.back()["best_epoch"].get<std::int64_t>(), result.best_epoch);

  expect_error_in_config(dir, "sequences.val_fraction=-0.5", "sequences.val_fraction=-0.5", "≥ 0");
  expect_error_in_config(dir, "sequences.val_fraction=0.7", "sequences.val_fraction=0.7",
                         "0.7 + 0.3 must be < 1");
  // configs/bdlstm/task.yaml's val_fraction: 0.1 with a test_fraction of 0.9.
  expect_error_in_config(dir, "sequences.test_fraction=0.9", "task.yaml", "0.1 + 0.9 must be < 1");
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
  // Selected on vae_loss over the validation frames (every validation window, 1 frame or more).
  ASSERT_TRUE(trainer.has_validation());
  for (const auto& m : metrics) {
    ASSERT_TRUE(m["val_loss"].is_number()) << m.dump();
    EXPECT_EQ(m["val_parts"].count("bidir"), 0u);
    EXPECT_EQ(m["val_parts"].count("recon"), 1u);
  }
  EXPECT_EQ(metrics.back()["best_epoch"].get<std::int64_t>(), argmin_epoch(metrics, "val_loss"));
  eval::EvalOptions eval_options;
  const eval::EvalReport report = evaluate_sequence(run, eval_options);
  EXPECT_GT(report.mean.at("e5_2if_mm"), 0);
  EXPECT_GT(report.mean.at("starts5"), 0);
  EXPECT_EQ(report.mean.count("e5_1if_mm"), 0u);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::bdlstm

// The corrective task's training and evaluation (experiments/densegats/corrective_task.hpp) on
// the bundled real bipeds: windows are induced subgraphs, evaluation poses are evenly spaced,
// the LBS and DQS rows are their errors against Delta Mush, training lowers the loss, an
// interrupted run resumes to the same parameters (the plateau schedule included), and bad
// configs fail before anything is written.
#include "experiments/densegats/corrective_task.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "framework/core/error.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/geometry/dqs.hpp"
#include "tests/densegats/densegats_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::densegats {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using CorrectiveTaskTest = BundledBipeds;
namespace fs = std::filesystem;

TEST(CorrectiveWindow, IsTheInducedSubgraphRenumbered) {
  CorrectiveSample s;
  s.features = torch::arange(12, torch::kFloat32).reshape({6, 2});
  s.displacement_t = torch::arange(18, torch::kFloat32).reshape({6, 3});
  // A path 0-1-2-3-4-5, both directions, receiver-sorted.
  const torch::Tensor edges = torch::tensor({0, 1, 1, 0, 1, 2, 2, 1, 2, 3, 3, 2, 3, 4, 4, 3, 4, 5, 5, 4},
                                            torch::kInt64)
                                  .reshape({10, 2});
  const Window w = window_of(s, edges, 2, 3);  // vertices 2, 3, 4
  EXPECT_TRUE(w.features.equal(s.features.narrow(0, 2, 3)));
  EXPECT_TRUE(w.target.equal(s.displacement_t.narrow(0, 2, 3)));
  EXPECT_EQ(w.graph.num_vertices, 3);
  EXPECT_TRUE(w.graph.one_ring.equal(torch::tensor({0, 1, 1, 0, 1, 2, 2, 1}, torch::kInt64).reshape({4, 2})))
      << w.graph.one_ring;
}

TEST(CorrectivePoses, EvaluationPosesAreEvenlySpaced) {
  CorrectiveCharacter c;
  c.poses.resize(10);
  EXPECT_EQ(eval_pose_indices(c, 4), (std::vector<int>{0, 2, 5, 7}));
  EXPECT_EQ(eval_pose_indices(c, 20).size(), 10u);
}

/// The smoke config on the prepared bipeds, results in `dir`.
config::Config smoke(const std::string& file, const skinlab::testing::TempDir& dir,
                     std::vector<std::string> extra = {}) {
  std::vector<std::string> overrides = {"data.file=" + file, "results_dir=" + dir.path().string()};
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  return config::Config::load(std::string(SKINLAB_SOURCE_DIR) + "/configs/densegats/smoke.yaml",
                              overrides);
}

std::vector<torch::Tensor> parameters_of(models::CorrectiveModel& model) {
  std::vector<torch::Tensor> out;
  for (const auto& p : model.parameters()) out.push_back(p.detach().clone());
  return out;
}

TEST_F(CorrectiveTaskTest, TrainingLowersTheLossAndResumesToTheSameParameters) {
  skinlab::testing::TempDir dir;
  const std::vector<std::string> four = {"train.epochs=4", "corrective.samples_per_epoch=8"};
  const config::Config config = smoke(file_, dir, four);
  const auto options = train::RunOptions::from(config);

  CorrectiveTrainer whole(config);
  const double before = whole.validation_loss();
  const RunDir a = train::create_run(config, options, "whole", {});
  const train::TrainResult r = whole.fit(a);
  EXPECT_EQ(r.epochs, 4);
  EXPECT_LT(whole.validation_loss(), before);
  EXPECT_TRUE(fs::exists(a.file("best.pt")));
  EXPECT_EQ(a.read_metrics().size(), 4u);

  const RunDir b = train::create_run(config, options, "resumed", {});
  {
    CorrectiveTrainer first(config);
    train::FitLimits stop;
    stop.stop_after_epochs = 2;
    EXPECT_TRUE(first.fit(b, stop).interrupted);
  }
  CorrectiveTrainer second(config);
  const train::TrainResult resumed = second.fit(b);
  EXPECT_TRUE(resumed.resumed);
  EXPECT_EQ(resumed.epochs_this_call, 2);
  const auto p = parameters_of(whole.model()), q = parameters_of(second.model());
  ASSERT_EQ(p.size(), q.size());
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_TRUE(p[i].equal(q[i])) << "parameter " << i;
}

TEST_F(CorrectiveTaskTest, ThePlateauScheduleDecaysToItsFloorAndSurvivesAResume) {
  // With lr 1e-30 (steps below float32 resolution) and no batch statistics nothing changes, so
  // every epoch after the first is a bad one: with patience 1 the third epoch decays the rate
  // to max(1e-30 · 0.5, 1e-7) = the floor.
  skinlab::testing::TempDir dir;
  const config::Config config =
      smoke(file_, dir, {"train.lr=1.0e-30", "train.epochs=4", "train.patience=0", "model.batch_norm=false",
                         "corrective.plateau={factor: 0.5, patience: 1, min_lr: 1.0e-7}"});
  const RunDir run = train::create_run(config, train::RunOptions::from(config), "plateau", {});
  {
    CorrectiveTrainer first(config);
    train::FitLimits stop;
    stop.stop_after_epochs = 3;
    first.fit(run, stop);
  }
  CorrectiveTrainer second(config);
  second.fit(run);
  const auto records = run.read_metrics();
  ASSERT_EQ(records.size(), 4u);
  EXPECT_EQ(records[2]["lr"].get<double>(), 1e-30);  // decayed after epoch 3 ...
  EXPECT_EQ(records[3]["lr"].get<double>(), 1e-7);  // ... and resumed with it
}

TEST_F(CorrectiveTaskTest, TheLbsAndDqsRowsAreTheirErrorsAgainstDeltaMush) {
  skinlab::testing::TempDir dir;
  const std::string configs = std::string(SKINLAB_SOURCE_DIR) + "/configs/densegats/";
  const std::vector<std::string> overrides = {"data.file=" + file_,
                                              "results_dir=" + dir.path().string(),
                                              "corrective.eval_poses=3"};
  const config::Config lbs_config = config::Config::load(configs + "lbs.yaml", overrides);
  const config::Config dqs_config = config::Config::load(configs + "dqs.yaml", overrides);
  const RunDir lbs_run = train::create_run(lbs_config, train::RunOptions::from(lbs_config), "lbs", {});
  const RunDir dqs_run = train::create_run(dqs_config, train::RunOptions::from(dqs_config), "dqs", {});
  eval::EvalOptions test;
  const eval::EvalReport lbs = evaluate_corrective(lbs_run, test);
  const eval::EvalReport dqs = evaluate_corrective(dqs_run, test);
  ASSERT_EQ(lbs.characters.size(), 1u);
  EXPECT_TRUE(fs::exists(lbs_run.file("eval_test.json")));

  // Recompute both rows by hand on the same poses.
  const CorrectiveData data(*dataset_, file_, CorrectiveConfig::from(lbs_config).corrective);
  const int c = data.members(dataset_->splits.at("random").test).at(0);
  const CorrectiveCharacter& ch = data.characters()[static_cast<std::size_t>(c)];
  double lbs_sum = 0, dqs_max = 0;
  std::size_t n = 0;
  for (int pose : eval_pose_indices(ch, 3)) {
    const CorrectiveSample s = data.sample(c, pose);
    lbs_sum += s.displacement.rowwise().norm().sum();
    n += static_cast<std::size_t>(s.lbs.rows());
    const Eigen::MatrixXd d = geometry::dqs(ch.mesh.V, ch.weights, data.transforms(c, pose));
    dqs_max = std::max(dqs_max, ((d - s.target) * data.cm_per_unit()).rowwise().norm().maxCoeff());
  }
  EXPECT_NEAR(lbs.characters[0].values.at("mean_error_cm"), lbs_sum / static_cast<double>(n), 1e-9);
  EXPECT_NEAR(dqs.characters[0].values.at("max_error_cm"), dqs_max, 1e-9);
  EXPECT_EQ(lbs.characters[0].values.at("poses"), 3);
  EXPECT_FALSE(lbs.characters[0].values.count("loss"));
}

TEST_F(CorrectiveTaskTest, BadConfigsFailBeforeAnythingIsWritten) {
  skinlab::testing::TempDir dir;
  expect_error<ConfigError>([&] { CorrectiveTrainer(smoke(file_, dir, {"model.input_width=40"})); },
                            {"input_width", "40", "6 + 46 joints = 52"});
  expect_error<ConfigError>(
      [&] {
        CorrectiveTrainer(config::Config::load(
            std::string(SKINLAB_SOURCE_DIR) + "/configs/densegats/lbs.yaml", {"data.file=" + file_}));
      },
      {"lbs.yaml", "not trained", "skinlab eval"});
  expect_error<IoError>([&] { CorrectiveTrainer(smoke(file_, dir, {"corrective.skeleton=Horse"})); },
                        {file_, "no character of skeleton family 'Horse'"});
  expect_error<ConfigError>([&] { CorrectiveTrainer(smoke(file_, dir, {"task=skinning"})); },
                            {"corrective"});
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::densegats

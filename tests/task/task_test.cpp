// The task registry (framework/task/task.hpp): a new paper's task is a plug-in that registers
// itself, owns its config section, trains, evaluates and tabulates, with no framework edit.
// This file is such a plug-in: the tiny task `counting`, whose "training" counts epochs and
// whose evaluation reports them.

#include "framework/task/task.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/eval/value_display.hpp"
#include "framework/train/run_options.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::expect_error;
using testing::TempDir;

/// Trains nothing: `fit` records `counting.epochs` epochs in the run's metrics.
class CountingTrainer final : public task::TaskTrainer {
 public:
  explicit CountingTrainer(int epochs) : epochs_(epochs) {}
  train::TrainResult fit(const RunDir& run, const train::FitLimits&) override {
    for (int e = 1; e <= epochs_; ++e) run.append_metrics({{"epoch", e}});
    train::TrainResult r;
    r.epochs = r.epochs_this_call = r.best_epoch = epochs_;
    return r;
  }
  bool validated() const override { return false; }

 private:
  int epochs_;
};

int epochs_of(const train::RunOptions& options) {
  int epochs = 1;
  config::Fields f(options.task_section, "counting");
  f.optional("epochs", epochs).check(epochs >= 1, "epochs", "must be ≥ 1");
  f.finish();
  return epochs;
}

class CountingTask final : public task::Task {
 public:
  std::string name() const override { return "counting"; }
  std::string section() const override { return "counting"; }
  void check_model(const config::Node&) const override {}
  void require_training_sections(const config::Config&, const train::RunOptions&) const override {}
  std::unique_ptr<task::TaskTrainer> trainer(const config::Config& config,
                                             train::World*) const override {
    return std::make_unique<CountingTrainer>(epochs_of(train::RunOptions::from(config)));
  }
  eval::EvalReport evaluate(const RunDir& run, const eval::EvalOptions& options) const override {
    eval::EvalReport r;
    r.part = options.part;
    eval::CharacterResult c;
    c.name = "only";
    c.values["epochs_trained"] = static_cast<double>(run.read_metrics().size());
    r.characters.push_back(c);
    return r;
  }
  std::string table(const std::vector<report::RunResult>& runs,
                    const report::TableOptions&) const override {
    return "counting table of " + std::to_string(runs.size()) + " runs\n";
  }
};

SKINLAB_REGISTER_TASK(counting, CountingTask);
SKINLAB_DECLARE_VALUE({"epochs_trained", "Epochs", "", true, false, 0});

config::Config counting_config(const std::string& extra = "") {
  return config::Config::parse("experiment: count\ntask: counting\ncounting: {epochs: 3}\n" + extra);
}

TEST(Task, ANewTaskIsRegisteredBesideTheFrameworksOwn) {
  verify_registries();
  const std::vector<std::string> keys = task_registry().keys();
  EXPECT_NE(std::find(keys.begin(), keys.end(), "counting"), keys.end());
  EXPECT_NE(std::find(keys.begin(), keys.end(), "skinning"), keys.end());
  EXPECT_EQ(task::get("counting").name(), "counting");
  EXPECT_EQ(&task::of(counting_config()), &task::get("counting"));
  EXPECT_EQ(task::of(config::Config::parse("experiment: x\n")).name(), "skinning");
  expect_error<RegistryError>([] { task::get("no_such_task"); }, {"no_such_task", "counting"});
}

TEST(Task, OwnsItsConfigSection) {
  const train::RunOptions o = train::RunOptions::from(counting_config());
  EXPECT_EQ(o.task, "counting");
  ASSERT_TRUE(o.task_section.exists());
  EXPECT_EQ(epochs_of(o), 3);
  // The section is the task's: a skinning config that has one is refused, naming both.
  expect_error<ConfigError>(
      [] { train::RunOptions::from(config::Config::parse("experiment: x\ncounting: {epochs: 2}\n")); },
      {"'counting' section", "task: counting"});
  expect_error<ConfigError>(
      [] { train::RunOptions::from(config::Config::parse("experiment: x\ntask: nope\n")); },
      {"task", "counting", "skinning"});
}

TEST(Task, TrainsEvaluatesAndTabulatesThroughTheRegistry) {
  TempDir dir;
  const config::Config config = counting_config("results_dir: " + dir.path().string() + "\n");
  const RunDir run = RunDir::create(dir.path(), "count", "r1");
  run.write_config(config.to_yaml());
  const auto trainer = task::make_trainer(config);
  EXPECT_EQ(trainer->fit(run, {}).epochs, 3);
  eval::EvalOptions e;
  e.part = "test";
  const eval::EvalReport report = task::evaluate_run(run, e);
  ASSERT_EQ(report.characters.size(), 1u);
  EXPECT_EQ(report.characters[0].values.at("epochs_trained"), 3.0);

  report::RunResult r;
  r.task = "counting";
  EXPECT_EQ(task::table_text({r, r}, {}), "counting table of 2 runs\n");
  // A task that is not data-parallel refuses train.batch and several processes.
  expect_error<ConfigError>([] { task::make_trainer(counting_config("train: {batch: 2}\n")); },
                            {"train.batch", "counting"});
  expect_error<Error>(
      [] {
        task::require_data_parallel(task::get("counting"), "c.yaml", "sharded evaluation",
                                    "is evaluated in one process");
      },
      {"c.yaml", "skinning task's", "a counting run is evaluated in one process"});
  // A task without figures says so.
  expect_error<Error>([] { task::get("counting").figures({}); }, {"counting", "no figures"});
}

TEST(Task, CommandOptionsParseWholeValuesOrSayWhich) {
  const std::map<std::string, std::string> values = {{"frames", "15"}, {"fps", "2.5"},
                                                     {"bad", "3x"}, {"clip", "walk"}};
  EXPECT_EQ(task::int_option(values, "frames"), 15);
  EXPECT_DOUBLE_EQ(task::double_option(values, "fps"), 2.5);
  EXPECT_EQ(task::string_option(values, "clip"), "walk");
  EXPECT_EQ(task::string_option(values, "start", "none"), "none");
  expect_error<Error>([&] { task::int_option(values, "bad"); }, {"--bad", "an integer", "'3x'"});
  expect_error<Error>([&] { task::double_option(values, "clip"); }, {"--clip", "a number"});
  expect_error<Error>([&] { task::int_option(values, "start"); }, {"--start", "needs a value"});
}

TEST(ValueDisplay, MetricsDeclareHowTheirValuesAreShown) {
  EXPECT_EQ(eval::value_display("epochs_trained").column_header(), "Epochs ↑");
  EXPECT_EQ(eval::value_display("precision").column_header(), "Precision ↑");
  EXPECT_TRUE(eval::value_display("precision").percent);
  EXPECT_EQ(eval::value_display("avg_l1").column_header(), "L1-norm ↓");
  EXPECT_EQ(eval::value_display("mean_error_cm").column_header(), "Mean err. (cm) ↓");
  EXPECT_FALSE(eval::value_display("undeclared_value").declared);
  EXPECT_EQ(eval::value_display("undeclared_value").column_header(), "undeclared_value");
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

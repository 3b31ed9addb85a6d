// The trainer on tiny synthetic characters with the test-only model `test_vertex_mlp`: the loss
// decreases, runs are deterministic, a resumed run (stopped in-process or killed with SIGKILL)
// ends bit-identical to an uninterrupted one, checkpoints are never partial, early stopping, and
// clear errors for bad configs, data and checkpoints.

#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "framework/tensors/threads.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/registry.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/trainer.hpp"
#include "tests/test_util.hpp"
#include "tests/train/test_model.hpp"
#include "tests/train/train_fixtures.hpp"

SKINLAB_REGISTER(model, test_vertex_mlp, skinlab::testing::TestVertexMlp);

extern char** environ;

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using testing::expect_error;
using testing::TempDir;

/// One dataset for every test of this file: 6 train, 2 val, 2 test tubes.
const fs::path& dataset() {
  static TempDir dir;
  static const fs::path file = [] {
    const fs::path f = dir / "tubes.h5";
    testing::write_tube_dataset(f, 6, 2, 2);
    return f;
  }();
  return file;
}

config::Config tube_config(const fs::path& results, const std::vector<std::string>& overrides = {}) {
  config::Config c = config::Config::parse(testing::tube_config(dataset(), results), "tubes.yaml");
  for (const auto& o : overrides) c.apply_override(o);
  return c;
}

train::TrainResult train_run(const config::Config& config, const std::string& run_id,
                             const train::FitLimits& limits = {}) {
  train::Trainer trainer(config);
  const RunDir run = train::create_run(config, trainer.options(), run_id, {"test"});
  return trainer.fit(run, limits);
}

RunDir run_dir(const fs::path& results, const std::string& id) {
  return RunDir::open(results / "tubes" / id);
}

/// The parameters stored in a checkpoint, by name.
std::map<std::string, torch::Tensor> parameters(const config::Config& config, const fs::path& checkpoint) {
  const auto options = train::RunOptions::from(config);
  auto model = train::build_model(options);
  train::load_checkpoint(checkpoint, *model);
  std::map<std::string, torch::Tensor> out;
  for (const auto& p : model->named_parameters()) out[p.key()] = p.value().detach().clone();
  return out;
}

void expect_identical(const std::map<std::string, torch::Tensor>& a,
                      const std::map<std::string, torch::Tensor>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, t] : a) {
    ASSERT_TRUE(b.count(name)) << name;
    EXPECT_TRUE(torch::equal(t, b.at(name))) << name << " differs";
  }
}

/// metrics.jsonl without the wall-clock field.
std::vector<nlohmann::json> records(const RunDir& run) {
  auto out = run.read_metrics();
  for (auto& r : out) r.erase("seconds");
  return out;
}

class Training : public ::testing::Test {
 protected:
  void SetUp() override { set_torch_threads(2); }
  TempDir results_;
};

TEST_F(Training, LossDecreasesOnAFixedSeed) {
  const auto config = tube_config(results_.path(), {"train.epochs=8"});
  const train::TrainResult r = train_run(config, "a");
  EXPECT_EQ(r.epochs, 8);
  EXPECT_EQ(r.epochs_this_call, 8);
  EXPECT_FALSE(r.resumed);
  const auto m = run_dir(results_.path(), "a").read_metrics();
  ASSERT_EQ(m.size(), 8u);
  EXPECT_EQ(m[0]["epoch"], 1);
  EXPECT_EQ(m[0]["characters"], 6);
  EXPECT_LT(m.back()["train_loss"].get<double>(), 0.7 * m.front()["train_loss"].get<double>());
  EXPECT_LT(m.back()["val_loss"].get<double>(), m.front()["val_loss"].get<double>());
  for (const char* key : {"kl", "laplacian_smoothing"}) {
    EXPECT_TRUE(m[0]["train_parts"].contains(key)) << m[0].dump();
    EXPECT_TRUE(m[0]["val_parts"].contains(key)) << m[0].dump();
  }
  EXPECT_TRUE(m[0].contains("seconds"));
  // best.pt holds the best validation loss of the records.
  double best = 1e300;
  int best_epoch = 0;
  for (const auto& rec : m) {
    if (rec["val_loss"].get<double>() < best) {
      best = rec["val_loss"];
      best_epoch = rec["epoch"];
    }
  }
  EXPECT_EQ(r.best_epoch, best_epoch);
  EXPECT_DOUBLE_EQ(r.best_loss, best);
}

TEST_F(Training, RunDirectoryHoldsConfigEnvMetricsAndCheckpointsWithoutTemporaries) {
  const auto config = tube_config(results_.path(), {"train.epochs=2"});
  train_run(config, "a");
  const RunDir run = run_dir(results_.path(), "a");
  for (const char* f : {"config.yaml", "env.json", "metrics.jsonl", "best.pt", "last.pt"})
    EXPECT_TRUE(fs::exists(run.file(f))) << f;
  for (const auto& e : fs::directory_iterator(run.path()))
    EXPECT_NE(e.path().filename().string()[0], '.') << "temporary left: " << e.path();
  EXPECT_NE(read_file(run.file("config.yaml")).find("test_vertex_mlp"), std::string::npos);
  const auto env = nlohmann::json::parse(read_file(run.file("env.json")));
  EXPECT_EQ(env["seed"], 7);
  EXPECT_EQ(env["threads"], 2);
}

TEST_F(Training, TwoRunsWithTheSameSeedGiveIdenticalWeights) {
  const auto config = tube_config(results_.path(), {"train.epochs=3"});
  train_run(config, "a");
  train_run(config, "b");
  expect_identical(parameters(config, run_dir(results_.path(), "a").file("last.pt")),
                   parameters(config, run_dir(results_.path(), "b").file("last.pt")));
  EXPECT_EQ(records(run_dir(results_.path(), "a")), records(run_dir(results_.path(), "b")));
  // ...and another seed does not.
  const auto other = tube_config(results_.path(), {"train.epochs=3", "seed=8"});
  train_run(other, "c");
  const auto a = parameters(config, run_dir(results_.path(), "a").file("last.pt"));
  const auto c = parameters(config, run_dir(results_.path(), "c").file("last.pt"));
  EXPECT_FALSE(torch::equal(a.at("input.weight"), c.at("input.weight")));
}

TEST_F(Training, InterleavedTrainersStayDeterministic) {
  // Building a second trainer (which reseeds libtorch) before the first trains changes nothing.
  const auto config = tube_config(results_.path(), {"train.epochs=2"});
  train_run(config, "a");
  train::Trainer first(config);
  train::Trainer second(tube_config(results_.path(), {"train.epochs=2", "seed=99"}));
  first.fit(train::create_run(config, first.options(), "b", {"test"}));
  expect_identical(parameters(config, run_dir(results_.path(), "a").file("last.pt")),
                   parameters(config, run_dir(results_.path(), "b").file("last.pt")));
}

TEST_F(Training, ResumedRunEqualsTheUninterruptedOne) {
  const auto config = tube_config(results_.path(), {"train.epochs=4"});
  train_run(config, "straight");
  const train::TrainResult first = train_run(config, "resumed", {/*stop_after_epochs=*/2});
  EXPECT_TRUE(first.interrupted);
  EXPECT_EQ(first.epochs, 2);
  const RunDir run = run_dir(results_.path(), "resumed");
  EXPECT_EQ(run.read_metrics().size(), 2u);

  train::Trainer again(config);
  const train::TrainResult second = again.fit(run);
  EXPECT_TRUE(second.resumed);
  EXPECT_EQ(second.epochs, 4);
  EXPECT_EQ(second.epochs_this_call, 2);
  const RunDir straight = run_dir(results_.path(), "straight");
  for (const char* ckpt : {"last.pt", "best.pt"}) {
    expect_identical(parameters(config, straight.file(ckpt)), parameters(config, run.file(ckpt)));
  }
  EXPECT_EQ(records(straight), records(run));
  // env.json keeps the start's record and lists the resume with the code it ran on.
  const nlohmann::json env = nlohmann::json::parse(read_file(run.file("env.json")));
  EXPECT_EQ(env["command"], nlohmann::json::array({"test"}));
  ASSERT_TRUE(env.contains("resumes"));
  ASSERT_EQ(env["resumes"].size(), 1u);
  EXPECT_EQ(env["resumes"][0]["after_epoch"], 2);
  EXPECT_EQ(env["resumes"][0]["git_commit"], env["git_commit"]);
  EXPECT_TRUE(env["resumes"][0].contains("time_utc"));
  EXPECT_FALSE(nlohmann::json::parse(read_file(straight.file("env.json"))).contains("resumes"));
}

TEST_F(Training, ResumeDropsMetricsOfAnEpochWithoutCheckpoint) {
  const auto config = tube_config(results_.path(), {"train.epochs=3"});
  train_run(config, "straight");
  train_run(config, "killed", {2});
  const RunDir run = run_dir(results_.path(), "killed");
  // A process killed after logging epoch 3 but before writing its checkpoint.
  run.append_metrics({{"epoch", 3}, {"train_loss", 123.0}});
  train::Trainer again(config);
  again.fit(run);
  EXPECT_EQ(records(run_dir(results_.path(), "straight")), records(run));
}

TEST_F(Training, EarlyStoppingAndResumingAFinishedRun) {
  // min_delta so large that nothing after epoch 1 counts as an improvement.
  const auto config =
      tube_config(results_.path(), {"train.epochs=10", "train.patience=2", "train.min_delta=1.0e9"});
  const train::TrainResult r = train_run(config, "a");
  EXPECT_TRUE(r.early_stopped);
  EXPECT_EQ(r.epochs, 3);
  EXPECT_EQ(r.best_epoch, 1);
  train::Trainer again(config);
  const train::TrainResult s = again.fit(run_dir(results_.path(), "a"));
  EXPECT_TRUE(s.resumed);
  EXPECT_EQ(s.epochs_this_call, 0);
  EXPECT_EQ(s.epochs, 3);
  EXPECT_EQ(run_dir(results_.path(), "a").read_metrics().size(), 3u);
  // Opening a finished run trains nothing and so records no resume.
  EXPECT_FALSE(nlohmann::json::parse(read_file(run_dir(results_.path(), "a").file("env.json")))
                   .contains("resumes"));
}

TEST_F(Training, MaxCharactersPerEpochAndNoValidationPart) {
  TempDir dir;
  const fs::path no_val = dir / "no_val.h5";
  testing::write_tube_dataset(no_val, 3, 0, 1);
  const auto config = tube_config(results_.path(), {"train.epochs=2", "train.max_characters_per_epoch=2",
                                                    "data.file=" + no_val.string()});
  const train::TrainResult r = train_run(config, "a");
  const auto m = run_dir(results_.path(), "a").read_metrics();
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0]["characters"], 2);
  EXPECT_TRUE(m[0]["val_loss"].is_null());
  EXPECT_GE(r.best_epoch, 1);  // selected on the train loss
  EXPECT_DOUBLE_EQ(r.best_loss, m[static_cast<std::size_t>(r.best_epoch - 1)]["train_loss"].get<double>());
}

TEST_F(Training, CheckpointsStoreTheTrainingState) {
  const auto config = tube_config(results_.path(), {"train.epochs=2"});
  const train::TrainResult r = train_run(config, "a");
  const auto options = train::RunOptions::from(config);
  auto model = train::build_model(options);
  const train::TrainingState s = train::load_checkpoint(run_dir(results_.path(), "a").file("last.pt"), *model);
  EXPECT_EQ(s.epoch, 2);
  EXPECT_EQ(s.best_epoch, r.best_epoch);
  EXPECT_EQ(s.best_loss, r.best_loss);
  EXPECT_EQ(s.seed, 7);
  EXPECT_EQ(s.threads, 2);
  EXPECT_TRUE(s.torch_rng.defined());
  EXPECT_TRUE(s.order_rng.defined());
  EXPECT_NE(s.model_config.find("test_vertex_mlp"), std::string::npos);
}

TEST_F(Training, UnreadableAndMismatchedCheckpointsAreClearErrors) {
  const auto config = tube_config(results_.path(), {"train.epochs=1"});
  train_run(config, "a");
  const RunDir run = run_dir(results_.path(), "a");
  auto narrow = train::build_model(train::RunOptions::from(tube_config(results_.path(), {"model.hidden=8"})));
  expect_error<IoError>([&] { train::load_checkpoint(run.file("best.pt"), *narrow); },
                        {"best.pt: checkpoint does not match the model: parameter 'input.weight' is "
                         "[16, 6] in the checkpoint but [8, 6] in the model",
                         "hidden: 16"});
  const std::string bytes = read_file(run.file("last.pt"));
  write_file_atomic(run.file("truncated.pt"), bytes.substr(0, bytes.size() / 2));
  auto model = train::build_model(train::RunOptions::from(config));
  expect_error<IoError>([&] { train::load_checkpoint(run.file("truncated.pt"), *model); },
                        {"truncated.pt: not a readable checkpoint"});
  expect_error<IoError>([&] { train::load_checkpoint(run.file("nothing.pt"), *model); },
                        {"nothing.pt: checkpoint does not exist"});
  // Resuming with another seed is refused.
  train::Trainer other(tube_config(results_.path(), {"train.epochs=2", "seed=3"}));
  expect_error<Error>([&] { other.fit(run); }, {"trained with seed 7, the config says 3"});
}

TEST(Checkpoint, ModuleNamesThatAreKeywordsAreRefusedBeforeTraining) {
  torch::nn::Module m;
  m.register_module("in", torch::nn::Linear(2, 2));
  expect_error<Error>([&] { train::check_checkpointable(m); },
                      {"parameter 'in.weight': the module name 'in' is a Python keyword"});
  TempDir dir;
  expect_error<Error>([&] { train::save_checkpoint(dir / "x.pt", m, nullptr, {}); },
                      {"Python keyword"});
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST_F(Training, BadConfigValuesAreClearErrors) {
  auto with = [&](const std::string& train_line) {
    std::string text = testing::tube_config(dataset(), results_.path());
    text.replace(text.find("train: {"), std::string::npos, train_line + "\n");
    return config::Config::parse(text, "tubes.yaml");
  };
  expect_error<ConfigError>([&] { train::Trainer t(with("train: {epochs: 0}")); },
                            {"tubes.yaml:9: train.epochs: must be ≥ 1"});
  expect_error<ConfigError>([&] { train::Trainer t(with("train: {lr: -1.0}")); },
                            {"tubes.yaml:9: train.lr: must be a positive number"});
  expect_error<ConfigError>([&] { train::Trainer t(with("train: {pateince: 3}")); },
                            {"tubes.yaml:9: train.pateince: unknown field of the train section",
                             "did you mean 'patience'?"});
  expect_error<ConfigError>([&] { train::Trainer t(with("train: {epochs: many}")); },
                            {"train.epochs: expected an integer, got 'many'"});
  expect_error<ConfigError>([&] { train::Trainer t(tube_config(results_.path(), {"data.fiel=x.h5"})); },
                            {"data.fiel: unknown field of the data section"});
  expect_error<ConfigError>(
      [&] { train::Trainer t(tube_config(results_.path(), {"data.distance=hollowdist"})); },
      {"data.distance: unknown distance type 'hollowdist'; known distance types: euclidean, "
       "hollow_dist"});
  expect_error<RegistryError>(
      [&] { train::Trainer t(tube_config(results_.path(), {"model.type=mlp"})); },
      {"unknown model type 'mlp'", "test_vertex_mlp"});
  const auto no_model = config::Config::parse("experiment: x\nlosses: [{type: kl}]\n"
                                              "data: {file: a.h5}\n", "nomodel.yaml");
  expect_error<ConfigError>([&] { train::Trainer t(no_model); },
                            {"nomodel.yaml: training needs a 'model' section"});
  const auto no_file = config::Config::parse("experiment: x\ndata: {split: random}\n", "nofile.yaml");
  expect_error<ConfigError>([&] { train::RunOptions::from(no_file); },
                            {"nofile.yaml:2: data: missing required field 'file'"});
}

TEST_F(Training, MissingDatasetUnknownSplitAndMissingDistanceAreClearErrors) {
  expect_error<IoError>(
      [&] { train::Trainer t(tube_config(results_.path(), {"data.file=/nonexistent/tubes.h5"})); },
      {"/nonexistent/tubes.h5"});
  expect_error<IoError>(
      [&] { train::Trainer t(tube_config(results_.path(), {"data.split=by_skeleton"})); },
      {"no split 'by_skeleton' (data.split); the file has the splits: random"});
  expect_error<IoError>(
      [&] { train::Trainer t(tube_config(results_.path(), {"data.distance=hollow_dist"})); },
      {"character 'tube_0' has no distance type 'hollow_dist'", "prepared with: euclidean"});
  EXPECT_TRUE(!fs::exists(results_ / "tubes")) << "no run directory for a failed set-up";
}

// ---- a real kill ------------------------------------------------------------------------------

/// Runs in a child process (started by the test below): trains the run named by the environment.
TEST(TrainChild, DISABLED_FitFromEnvironment) {
  const char* config = std::getenv("SKINLAB_CHILD_CONFIG");
  const char* run = std::getenv("SKINLAB_CHILD_RUN");
  ASSERT_TRUE(config && run);
  set_torch_threads(2);
  train::Trainer trainer(config::Config::load(config));
  trainer.fit(RunDir::open(run));
}

pid_t spawn_child(const fs::path& config, const fs::path& run, const fs::path& log) {
  setenv("SKINLAB_CHILD_CONFIG", config.c_str(), 1);
  setenv("SKINLAB_CHILD_RUN", run.c_str(), 1);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::string exe = fs::read_symlink("/proc/self/exe").string();
  std::string filter = "--gtest_filter=TrainChild.DISABLED_FitFromEnvironment";
  std::string disabled = "--gtest_also_run_disabled_tests";
  char* argv[] = {exe.data(), filter.data(), disabled.data(), nullptr};
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("posix_spawn failed");
  return pid;
}

TEST_F(Training, KilledRunResumesToTheUninterruptedResultAndCheckpointsAreNeverPartial) {
  TempDir dir;
  const fs::path file = dir.write("tubes.yaml", testing::tube_config(dataset(), results_.path()) +
                                                    "");
  const std::vector<std::string> overrides = {"train.epochs=30"};
  config::Config config = config::Config::load(file, overrides);
  // The child reads the same file; the override is baked in by writing the resolved config.
  const fs::path resolved = dir.write("resolved.yaml", config.to_yaml());
  config = config::Config::load(resolved);
  train_run(config, "straight");

  const RunDir run = train::create_run(config, train::RunOptions::from(config), "killed", {"test"});
  int kills = 0;
  for (const std::size_t kill_after : {4u, 15u}) {
    const pid_t pid = spawn_child(resolved, run.path(), dir / "child.log");
    int status = 0;
    bool exited = false;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
      if (::waitpid(pid, &status, WNOHANG) == pid) {
        exited = true;
        break;
      }
      if (fs::exists(run.file("metrics.jsonl")) && run.read_metrics().size() >= kill_after) break;
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
    if (!exited) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      ++kills;
    } else {
      ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_file(dir / "child.log");
    }
    // Whatever the moment of the kill, every checkpoint under its name is complete.
    for (const char* ckpt : {"best.pt", "last.pt"}) {
      if (!fs::exists(run.file(ckpt))) continue;
      auto model = train::build_model(train::RunOptions::from(config));
      EXPECT_NO_THROW(train::load_checkpoint(run.file(ckpt), *model)) << ckpt;
    }
  }
  EXPECT_GE(kills, 1) << "the child finished before any kill; the test did not interrupt it";
  train::Trainer last(config);
  const train::TrainResult r = last.fit(run);
  EXPECT_EQ(r.epochs, 30);
  const RunDir straight = run_dir(results_.path(), "straight");
  for (const char* ckpt : {"last.pt", "best.pt"}) {
    expect_identical(parameters(config, straight.file(ckpt)), parameters(config, run.file(ckpt)));
  }
  EXPECT_EQ(records(straight), records(run));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

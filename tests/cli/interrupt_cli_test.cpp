// Concurrent and interrupted use of the binaries (issue 25 item 6): a second `skinlab prepare`,
// `train --resume` or `eval` of an output another process is writing fails at once naming that
// process; SIGINT during prepare, train, eval or skinlab-predict ends the process by the signal
// and leaves no temporary file, no lock file and nothing half-written under a final name.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/core/output_lock.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/data/h5.hpp"
#include "tests/cli/cli_run.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using testing::Result;
using testing::run;
using testing::TempDir;

/// A binary started from the source directory with its stdout and stderr in files of `dir`.
class Process {
 public:
  Process(const TempDir& dir, const std::string& name, const std::string& binary,
          const std::vector<std::string>& args)
      : out_(dir / (name + ".out")), err_(dir / (name + ".err")) {
    pid_ = ::fork();
    if (pid_ == 0) {
      if (::chdir(SKINLAB_SOURCE_DIR) != 0) std::_Exit(126);
      const int out = ::open(out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err = ::open(err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(out, STDOUT_FILENO);
      ::dup2(err, STDERR_FILENO);
      std::vector<char*> argv{const_cast<char*>(binary.c_str())};
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(binary.c_str(), argv.data());
      std::_Exit(127);
    }
  }
  ~Process() {
    if (pid_ > 0 && !done_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  pid_t pid() const { return pid_; }
  std::string out() const { return fs::exists(out_) ? read_file(out_) : ""; }
  std::string err() const { return fs::exists(err_) ? read_file(err_) : ""; }

  /// Waits (up to two minutes) until `ready` holds; false if the process ended first.
  bool wait_until(const std::function<bool()>& ready) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(2);
    while (std::chrono::steady_clock::now() < deadline) {
      if (ready()) return true;
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        done_ = true;
        status_ = status;
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return false;
  }
  /// Sends `sig` and returns the wait status.
  int stop(int sig) {
    if (!done_) {
      ::kill(pid_, sig);
      ::waitpid(pid_, &status_, 0);
      done_ = true;
    }
    return status_;
  }

 private:
  fs::path out_, err_;
  pid_t pid_ = -1;
  bool done_ = false;
  int status_ = 0;
};

/// Every path under `dir` whose name marks a temporary or a lock file.
std::vector<std::string> leftovers(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    const bool lock = name.size() > 5 && name.substr(name.size() - 5) == ".lock";
    if (lock || name.find(".tmp-") != std::string::npos) {
      found.push_back(entry.path().string());
    }
  }
  return found;
}

/// Whether `dir` holds a file whose name ends in `suffix`.
bool has_file(const fs::path& dir, const std::string& suffix) {
  if (!fs::is_directory(dir)) return false;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.size() >= suffix.size() && name.substr(name.size() - suffix.size()) == suffix &&
        name[0] != '.') {
      return true;
    }
  }
  return false;
}

/// Whether `dir` holds a temporary file of AtomicPath.
bool has_temporary(const fs::path& dir) {
  if (!fs::is_directory(dir)) return false;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) return true;
  }
  return false;
}

void expect_interrupted(int status, const Process& p) {
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << WEXITSTATUS(status) << "\n" << p.err();
  EXPECT_EQ(WTERMSIG(status), SIGINT);
  EXPECT_NE(p.err().find("skinlab: interrupted by SIGINT; temporary files removed"),
            std::string::npos) << p.err();
}

const std::string kBusy = " is being written by pid ";

TEST(InterruptCli, ASecondWriterOfAnOutputBeingWrittenFailsAtOnceNamingTheFirst) {
  TempDir dir;
  const fs::path out = dir / "minetest.h5";
  const std::string owner = " (skinlab prepare first.yaml, started ";
  {
    const OutputLock held(lock_file_of(out), out.string(), {"skinlab", "prepare", "first.yaml"});
    const Result r = run("prepare configs/datasets/minetest.yaml output=" + out.string() +
                         " distances.0.resolution=32 --threads 2");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("skinlab: error: " + out.string() + kBusy + std::to_string(::getpid())),
              std::string::npos) << r.err;
    EXPECT_NE(r.err.find(owner), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("wait for it to finish or stop it"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(out.string() + ".partial")) << "it failed before any work";
  }
  // A run directory: `train --resume` and `eval` of the same part wait for nobody either.
  const fs::path run_dir = dir / "results" / "smoke" / "r";
  fs::create_directories(run_dir);
  write_file_atomic(run_dir / "config.yaml", "experiment: smoke\n");
  {
    const OutputLock held(run_dir / "train.lock", run_dir.string(), {"skinlab", "train", "first.yaml"});
    const Result r = run("train --resume " + run_dir.string());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("skinlab: error: " + run_dir.string() + kBusy + std::to_string(::getpid())),
              std::string::npos) << r.err;
  }
  {
    const fs::path json = run_dir / "eval_test.json";
    const OutputLock held(run_dir / "eval_test.lock", json.string(), {"skinlab", "eval", "r"});
    const Result r = run("eval " + run_dir.string() + " --split test");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("skinlab: error: " + json.string() + kBusy + std::to_string(::getpid())),
              std::string::npos) << r.err;
  }
  EXPECT_EQ(leftovers(dir.path()), std::vector<std::string>{});
}

TEST(InterruptCli, SigintDuringPrepareLeavesNoOutputAndItsFinishedCharactersAreReused) {
  TempDir dir;
  const fs::path out = dir / "bundled.h5";
  const fs::path partial = out.string() + ".partial";
  const std::vector<std::string> args = {"prepare", "configs/datasets/zeroad_bundled.yaml",
                                         "output=" + out.string(), "--threads", "1"};
  Process p(dir, "prepare", SKINLAB_CLI, args);
  // Working: at least one character preprocessed into its partial file.
  ASSERT_TRUE(p.wait_until([&] { return has_file(partial, ".h5"); })) << p.err();
  expect_interrupted(p.stop(SIGINT), p);
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(leftovers(dir.path()), std::vector<std::string>{});

  // The characters finished before the interruption are whole (the next run reuses them).
  int finished = 0;
  for (const auto& entry : fs::directory_iterator(partial)) {
    EXPECT_EQ(data::read_dataset(entry.path()).characters.size(), 1u) << entry.path();
    ++finished;
  }
  EXPECT_GE(finished, 1);
}

TEST(InterruptCli, SigintDuringTrainAndEvalLeavesWholeFilesAndNoLock) {
  TempDir dir;
  const std::string data = (dir / "minetest.h5").string();
  const Result p = run("prepare configs/datasets/minetest.yaml output=" + data +
                       " distances.0.resolution=32 --threads 2");
  ASSERT_EQ(p.status, 0) << p.err;
  const fs::path run_dir = dir / "results" / "smoke" / "int";
  Process train(dir, "train", SKINLAB_CLI,
                {"train", "configs/smoke.yaml", "data.file=" + data,
                 "results_dir=" + (dir / "results").string(), "train.epochs=100000",
                 "train.patience=0", "--run-id", "int", "--threads", "1"});
  // Working: the first epoch is recorded.
  ASSERT_TRUE(train.wait_until([&] { return fs::exists(run_dir / "last.pt"); })) << train.err();

  // A second trainer of the run fails at once, naming the first.
  const Result second = run("train --resume " + run_dir.string());
  EXPECT_EQ(second.status, 1);
  EXPECT_NE(second.err.find(run_dir.string() + kBusy + std::to_string(train.pid())),
            std::string::npos) << second.err;
  EXPECT_NE(second.err.find("train configs/smoke.yaml data.file="), std::string::npos) << second.err;

  expect_interrupted(train.stop(SIGINT), train);
  EXPECT_EQ(leftovers(dir.path()), std::vector<std::string>{});
  const RunDir run = RunDir::open(run_dir);
  EXPECT_GE(run.read_metrics().size(), 1u) << "every line whole";

  // Evaluation, interrupted while its predictions file is being written.
  Process eval(dir, "eval", SKINLAB_CLI,
               {"eval", run_dir.string(), "--split", "train", "--checkpoint", "last"});
  ASSERT_TRUE(eval.wait_until([&] { return has_temporary(run_dir / "predictions"); })) << eval.err();
  expect_interrupted(eval.stop(SIGINT), eval);
  EXPECT_EQ(leftovers(dir.path()), std::vector<std::string>{});
  EXPECT_FALSE(fs::exists(run_dir / "predictions" / "train.h5"));
  EXPECT_FALSE(fs::exists(run_dir / "eval_train.json"));
}

TEST(InterruptCli, SigintDuringABatchPredictionLeavesOnlyWholeOutputs) {
  TempDir dir;
  const fs::path in = dir / "in", out = dir / "out";
  fs::create_directories(in);
  const int n = 40;
  for (int k = 0; k < n; ++k) {
    fs::copy_file("/usr/share/games/minetest/games/minetest_game/mods/player_api/models/character.b3d",
                  in / ("c" + std::to_string(100 + k) + ".b3d"));
  }
  Process p(dir, "predict", SKINLAB_PREDICT_CLI,
            {in.string(), "--out-dir", out.string(), "--format", "h5", "--threads", "1"});
  ASSERT_TRUE(p.wait_until([&] { return has_file(out, ".h5"); })) << p.err();
  const int status = p.stop(SIGINT);
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << WEXITSTATUS(status) << "\n" << p.err();
  EXPECT_EQ(WTERMSIG(status), SIGINT);
  EXPECT_NE(p.err().find("skinlab-predict: interrupted by SIGINT"), std::string::npos) << p.err();
  EXPECT_EQ(leftovers(dir.path()), std::vector<std::string>{});
  int written = 0;
  for (const auto& entry : fs::directory_iterator(out)) {
    EXPECT_GT(data::H5Reader(entry.path()).read_double("weights").rows(), 0) << entry.path();
    ++written;
  }
  EXPECT_GE(written, 1);
  EXPECT_LT(written, n);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

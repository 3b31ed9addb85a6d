// Data-parallel training and sharded preparation through the real binary: two
// processes on localhost (c10d, Gloo) train the tiny HeterSkinNet on the bundled 0 A.D. subset
// to the same parameters as one process with the same effective batch; a worker that dies ends
// the run with a clear error at once, and the run resumes from its last checkpoint in another
// world size; `prepare --nproc 2` writes the same dataset as one process.

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <thread>
#include <nlohmann/json.hpp>

#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/launch.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/run_options.hpp"
#include "framework/train/trainer.hpp"
#include "tests/cli/cli_run.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::Result;
using testing::run;
using testing::TempDir;

std::vector<nlohmann::json> metrics_of(const std::filesystem::path& run_dir) {
  std::ifstream lines(run_dir / "metrics.jsonl");
  std::vector<nlohmann::json> out;
  for (std::string line; std::getline(lines, line);) out.push_back(nlohmann::json::parse(line));
  return out;
}

/// The parameters of a run's checkpoint, loaded into its model.
std::vector<torch::Tensor> parameters_of(const std::filesystem::path& run_dir, const char* checkpoint) {
  const config::Config config = config::Config::load(run_dir / "config.yaml");
  auto model = train::build_model(train::RunOptions::from(config));
  train::load_checkpoint(run_dir / checkpoint, *model);
  std::vector<torch::Tensor> out;
  for (const auto& p : model->parameters()) out.push_back(p.detach().clone());
  return out;
}

class Distributed : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    data_ = (*dir_ / "bundled.h5").string();
    // Euclidean distances only: this is about the processes, not the distance.
    const Result p = run("prepare configs/datasets/zeroad_bundled.yaml output=" + data_ +
                         " \"distances=[{type: euclidean}]\" --nproc 2");
    ASSERT_EQ(p.status, 0) << p.err;
  }
  static void TearDownTestSuite() { delete dir_; }

  /// The smoke config without dropout (so one and two processes see the same network), one
  /// thread per process, 2 epochs of 4 characters.
  static std::string train_args(const std::string& extra) {
    return "train configs/smoke.yaml data.file=" + data_ + " data.distance=euclidean results_dir=" +
           (*dir_ / "results").string() +
           " model.edge_dropout.p=0 model.head_dropout=0 train.epochs=2 threads=1 " + extra;
  }
  static std::filesystem::path run_dir(const std::string& id) { return *dir_ / "results" / "smoke" / id; }

  static inline TempDir* dir_ = nullptr;
  static inline std::string data_;
};

TEST_F(Distributed, ShardedPrepareWritesTheSameDatasetAsOneProcess) {
  const std::string single = (*dir_ / "single.h5").string();
  const Result p = run("prepare configs/datasets/zeroad_bundled.yaml output=" + single +
                       " \"distances=[{type: euclidean}]\" --threads 2");
  ASSERT_EQ(p.status, 0) << p.err;
  const data::Dataset a = data::read_dataset(data_), b = data::read_dataset(single);
  ASSERT_EQ(a.characters.size(), b.characters.size());
  EXPECT_GT(a.characters.size(), 5u);
  for (std::size_t i = 0; i < a.characters.size(); ++i) {
    EXPECT_EQ(a.characters[i].name, b.characters[i].name);
    EXPECT_EQ(a.characters[i].V, b.characters[i].V) << a.characters[i].name;
    EXPECT_EQ(a.characters[i].distances.at("euclidean").targets,
              b.characters[i].distances.at("euclidean").targets)
        << a.characters[i].name;
  }
  EXPECT_EQ(a.splits.at("random").train, b.splits.at("random").train);
  EXPECT_FALSE(std::filesystem::exists(data_ + ".partial"));  // merged and cleaned up
}

TEST_F(Distributed, TwoProcessesFollowOneProcessWithTheSameEffectiveBatch) {
  const Result one = run(train_args("train.batch=2 --run-id one"));
  ASSERT_EQ(one.status, 0) << one.err;
  const Result two = run(train_args("train.batch=1 --nproc 2 --run-id two"));
  ASSERT_EQ(two.status, 0) << two.err;
  const auto env = nlohmann::json::parse(read_file(run_dir("two") / "env.json"));
  EXPECT_EQ(env["world_size"], 2);

  const auto m1 = metrics_of(run_dir("one")), m2 = metrics_of(run_dir("two"));
  ASSERT_EQ(m1.size(), 2u);
  ASSERT_EQ(m2.size(), 2u);
  for (std::size_t e = 0; e < 2; ++e) {
    EXPECT_NEAR(m1[e]["train_loss"].get<double>(), m2[e]["train_loss"].get<double>(),
                1e-5 * std::abs(m1[e]["train_loss"].get<double>()));
    EXPECT_NEAR(m1[e]["val_loss"].get<double>(), m2[e]["val_loss"].get<double>(),
                1e-5 * std::abs(m1[e]["val_loss"].get<double>()));
    EXPECT_EQ(m2[e]["world_size"], 2);
  }
  const auto p1 = parameters_of(run_dir("one"), "last.pt"), p2 = parameters_of(run_dir("two"), "last.pt");
  ASSERT_EQ(p1.size(), p2.size());
  double largest = 0;
  for (std::size_t i = 0; i < p1.size(); ++i) {
    largest = std::max(largest, (p1[i] - p2[i]).abs().max().item<double>());
  }
  EXPECT_LT(largest, 1e-5) << "largest parameter difference";

  // Sharded evaluation: two processes score every character of the part as one does, and rank 0
  // writes the same files.
  const Result e1 = run("eval " + run_dir("one").string() + " --split test --threads 1");
  ASSERT_EQ(e1.status, 0) << e1.err;
  const auto single = nlohmann::json::parse(read_file(run_dir("one") / "eval_test.json"));
  const std::string rig = read_file(run_dir("one") / "predictions" / "test" /
                                    (single["per_character"][0]["character"].get<std::string>() + "_rig.txt"));
  const Result e2 = run("eval " + run_dir("one").string() + " --split test --nproc 2 --threads 1");
  ASSERT_EQ(e2.status, 0) << e2.err;
  const auto sharded = nlohmann::json::parse(read_file(run_dir("one") / "eval_test.json"));
  ASSERT_EQ(sharded["per_character"].size(), single["per_character"].size());
  for (std::size_t i = 0; i < single["per_character"].size(); ++i) {
    EXPECT_EQ(sharded["per_character"][i], single["per_character"][i]) << i;
  }
  EXPECT_EQ(sharded["mean"], single["mean"]);
  EXPECT_EQ(read_file(run_dir("one") / "predictions" / "test" /
                      (single["per_character"][0]["character"].get<std::string>() + "_rig.txt")),
            rig);
}

// Ranks started by hand with PyTorch's launcher environment (as a cluster job script starts one
// process per node) train the same run as `--nproc`.
TEST_F(Distributed, RanksStartedByHandWithTheLaunchersEnvironment) {
  const Result two = run(train_args("train.batch=1 --nproc 2 --run-id by-launcher"));
  ASSERT_EQ(two.status, 0) << two.err;
  const std::string env = fmt::format("WORLD_SIZE=2 MASTER_ADDR=127.0.0.1 MASTER_PORT={}", free_local_port());
  const std::string cli = std::string("'") + SKINLAB_CLI + "' ";
  const std::string args = train_args("train.batch=1 --run-id by-hand");
  const std::string command = std::string("cd '") + SKINLAB_SOURCE_DIR + "' && (" + env + " RANK=1 " +
                              cli + args + " > /dev/null 2>&1 &) && " + env + " RANK=0 " + cli + args +
                              " > /dev/null 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  for (int tries = 0; tries < 100 && metrics_of(run_dir("by-hand")).size() < 2; ++tries) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const auto metrics = metrics_of(run_dir("by-hand"));
  ASSERT_EQ(metrics.size(), 2u);
  EXPECT_EQ(metrics.back()["world_size"], 2);
  const auto p = parameters_of(run_dir("by-hand"), "last.pt"), q = parameters_of(run_dir("by-launcher"), "last.pt");
  ASSERT_EQ(p.size(), q.size());
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_TRUE(p[i].equal(q[i])) << "parameter " << i;
  // Without a shared run id the ranks could not find one run directory: an error at once.
  ::setenv("WORLD_SIZE", "2", 1);
  const Result no_id = run(train_args(""));
  ::unsetenv("WORLD_SIZE");
  EXPECT_NE(no_id.status, 0);
  EXPECT_NE(no_id.err.find("needs --run-id or --resume"), std::string::npos) << no_id.err;
}

TEST_F(Distributed, ADeadWorkerStopsTheRunAndItResumesInAnotherWorldSize) {
  // Rank 1 kills itself before its 4th step: 2 steps per epoch, so after epoch 1's checkpoint.
  ::setenv("SKINLAB_TEST_KILL", "1:3", 1);
  const auto start = std::chrono::steady_clock::now();
  const Result killed = run(train_args("--nproc 2 --run-id killed"));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ::unsetenv("SKINLAB_TEST_KILL");
  EXPECT_NE(killed.status, 0);
  EXPECT_NE(killed.err.find("worker rank 1 of 2"), std::string::npos) << killed.err;
  EXPECT_NE(killed.err.find("killed by signal 9"), std::string::npos) << killed.err;
  EXPECT_LT(seconds, 120) << "the survivors must not wait for the dead worker";
  ASSERT_EQ(metrics_of(run_dir("killed")).size(), 1u);
  EXPECT_TRUE(std::filesystem::exists(run_dir("killed") / "last.pt"));

  const Result resumed = run("train --resume " + run_dir("killed").string());
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  const auto metrics = metrics_of(run_dir("killed"));
  ASSERT_EQ(metrics.size(), 2u);
  EXPECT_FALSE(metrics.back().contains("world_size"));  // the second epoch ran in one process
}

TEST_F(Distributed, OnlyTheSkinningTaskTrainsDataParallel) {
  const Result r = run("train configs/bdlstm/smoke.yaml --nproc 2");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("skinning task's"), std::string::npos) << r.err;
  const Result b = run("train configs/bdlstm/smoke.yaml train.batch=2");
  EXPECT_NE(b.status, 0);
  EXPECT_NE(b.err.find("train.batch"), std::string::npos) << b.err;
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

#include "framework/core/run_dir.hpp"

#include <gtest/gtest.h>

#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::expect_error;
using testing::TempDir;

TEST(RunDir, WritesTheFourFiles) {
  TempDir dir;
  const RunDir run = RunDir::create(dir.path(), "heterskinnet", "run1");
  EXPECT_EQ(run.path(), dir / "heterskinnet/run1");
  EXPECT_EQ(run.id(), "run1");

  const auto config = config::Config::parse("experiment: heterskinnet\nseed: 3\n");
  run.write_config(config.to_yaml());
  run.write_env(collect_environment(3, {"skinlab", "train", "x.yaml"}));
  run.append_metrics({{"epoch", 1}, {"loss", 0.5}});
  run.append_metrics({{"epoch", 2}, {"loss", 0.25}});

  EXPECT_EQ(config::Config::load(run.file("config.yaml")).root()["seed"].as<int>(), 3);
  const auto env = nlohmann::json::parse(read_file(run.file("env.json")));
  for (const char* key : {"git_commit", "git_dirty", "build_type", "libraries", "threads", "seed",
                          "host", "time_utc", "command"}) {
    EXPECT_TRUE(env.contains(key)) << key;
  }
  EXPECT_EQ(env["seed"], 3);
  for (const char* lib : {"compiler", "eigen", "cgal", "hdf5"}) {
    EXPECT_FALSE(env["libraries"][lib].get<std::string>().empty()) << lib;
  }
  EXPECT_GE(env["threads"].get<int>(), 1);
  EXPECT_EQ(read_file(run.file("metrics.jsonl")),
            "{\"epoch\":1,\"loss\":0.5}\n{\"epoch\":2,\"loss\":0.25}\n");
  const auto records = run.read_metrics();
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[1]["loss"], 0.25);
}

TEST(RunDir, NeverOverwritesAnExistingRun) {
  TempDir dir;
  const RunDir first = RunDir::create(dir.path(), "exp", "same");
  first.write_config("seed: 1\n");
  expect_error<Error>([&] { RunDir::create(dir.path(), "exp", "same"); },
                      {"exp/same", "already exists"});
  EXPECT_EQ(read_file(first.file("config.yaml")), "seed: 1\n");
}

TEST(RunDir, GeneratedIdsAreUnique) {
  TempDir dir;
  const RunDir a = RunDir::create(dir.path(), "exp");
  const RunDir b = RunDir::create(dir.path(), "exp");
  const RunDir c = RunDir::create(dir.path(), "exp");
  EXPECT_NE(a.path(), b.path());
  EXPECT_NE(b.path(), c.path());
  EXPECT_EQ(a.id().size(), 15u);  // YYYYmmdd-HHMMSS
}

TEST(RunDir, RejectsBadNamesAndNonRuns) {
  TempDir dir;
  expect_error<Error>([&] { RunDir::create(dir.path(), "../escape"); }, {"experiment name"});
  expect_error<Error>([&] { RunDir::create(dir.path(), "exp", ".hidden"); }, {"run id '.hidden'"});
  expect_error<Error>([&] { RunDir::create(dir.path(), ""); }, {"experiment name ''"});
  std::filesystem::create_directories(dir / "not_a_run");
  expect_error<Error>([&] { RunDir::open(dir / "not_a_run"); }, {"not a run directory"});
  expect_error<Error>([&] { RunDir::open(dir / "absent"); }, {"does not exist"});
}

TEST(RunDir, MalformedMetricsLineIsNamed) {
  TempDir dir;
  const RunDir run = RunDir::create(dir.path(), "exp", "r");
  write_file_atomic(run.file("metrics.jsonl"), "{\"a\":1}\n{broken\n");
  expect_error<Error>([&] { run.read_metrics(); }, {"metrics.jsonl:2", "malformed JSON"});
  expect_error<Error>([&] { run.append_metrics(nlohmann::json::array()); }, {"JSON object"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

// RunData: the split a run trains and validates on, as stored or with its validation part drawn
// from chosen sources (`data.val_sources`).

#include <gtest/gtest.h>

#include "framework/core/config.hpp"
#include "framework/train/run_data.hpp"
#include "tests/test_util.hpp"
#include "tests/train/train_fixtures.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::expect_error;
using testing::TempDir;

/// Tubes 0-5 train, 6-7 validate, 8-9 test (split "random"); tubes 0, 1, 6 and 8 come from
/// source "small", the others from "big"; tube 2 is a variant of tube 0 (one group).
std::filesystem::path two_source_dataset(const TempDir& dir) {
  const auto file = dir.path() / "tubes.h5";
  testing::write_tube_dataset(file, 6, 2, 2);
  data::Dataset d = data::read_dataset(file);
  for (int i : {0, 1, 6, 8}) d.characters[static_cast<std::size_t>(i)].source = "small";
  for (int i : {2, 3, 4, 5, 7, 9}) d.characters[static_cast<std::size_t>(i)].source = "big";
  d.characters[2].group = d.characters[0].name;
  d.characters[0].group = d.characters[0].name;
  data::write_dataset(file, d);
  return file;
}

train::DataOptions options_for(const std::filesystem::path& file,
                               std::vector<std::string> val_sources) {
  train::DataOptions o;
  o.file = file.string();
  o.distance = "euclidean";
  o.val_sources = std::move(val_sources);
  return o;
}

TEST(RunData, TheStoredSplitWithoutValidationSources) {
  TempDir dir;
  const train::RunData data(options_for(two_source_dataset(dir), {}));
  EXPECT_EQ(data.part("train"), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(data.part("val"), (std::vector<int>{6, 7}));
  EXPECT_EQ(data.part("test"), (std::vector<int>{8, 9}));
}

TEST(RunData, ValidationSourcesTakeTheirGroupsOutOfTrainingAndLeaveTheTestAlone) {
  TempDir dir;
  const train::RunData data(options_for(two_source_dataset(dir), {"small"}));
  // 0, 1, 6 from "small", and 2 with its group; 7 (big) moves from validation to training;
  // test tube 8 is from "small" too and stays in the test part.
  EXPECT_EQ(data.part("val"), (std::vector<int>{0, 1, 2, 6}));
  EXPECT_EQ(data.part("train"), (std::vector<int>{3, 4, 5, 7}));
  EXPECT_EQ(data.part("test"), (std::vector<int>{8, 9}));
}

TEST(RunData, ValidationSourcesAreReadFromTheDataSection) {
  const config::Config c = config::Config::parse(
      "file: tubes.h5\nval_sources: [small, OGRECave/ogre]\n", "run.yaml");
  EXPECT_EQ(train::DataOptions::from(c.root()).val_sources,
            (std::vector<std::string>{"small", "OGRECave/ogre"}));
  EXPECT_TRUE(train::DataOptions::from(config::Config::parse("file: tubes.h5\n").root())
                  .val_sources.empty());
  expect_error<ConfigError>(
      [] { train::DataOptions::from(config::Config::parse("file: a.h5\nval_sources: 3\n", "run.yaml").root()); },
      {"run.yaml", "val_sources"});
}

TEST(RunData, AnAbsentValidationSourceOrNothingLeftToTrainIsAnErrorNamingTheFile) {
  TempDir dir;
  const auto file = two_source_dataset(dir);
  expect_error<IoError>([&] { train::RunData(options_for(file, {"smal"})); },
                        {file.string(), "split 'random', data.val_sources", "'smal'",
                         "sources there: big, small"});
  expect_error<IoError>([&] { train::RunData(options_for(file, {"small", "big"})); },
                        {file.string(), "data.val_sources", "nothing to train on"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

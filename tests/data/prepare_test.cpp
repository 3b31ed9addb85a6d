// `skinlab prepare` as a library call: the Minetest config end to end, resumability from a
// partial directory, and failures collected rather than fatal.

#include "framework/data/prepare.hpp"

#include <gtest/gtest.h>

#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/rig_io.hpp"
#include "tests/data/data_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::TempDir;

data::PrepareConfig minetest_config(const TempDir& dir,
                                    const std::vector<std::string>& extra = {}) {
  std::vector<std::string> overrides = {"output=" + (dir / "out/minetest.h5").string(),
                                        "distances=[{type: euclidean}]"};
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  return data::PrepareConfig::from(config::Config::load(
      std::string(SKINLAB_SOURCE_DIR) + "/configs/datasets/minetest.yaml", overrides));
}

data::PrepareOptions quiet(bool keep_partial) {
  data::PrepareOptions o;
  o.threads = 1;
  o.keep_partial = keep_partial;
  o.progress = false;
  return o;
}

TEST(Prepare, SecondRunReusesDoneCharacters) {
  TempDir dir;
  const auto config = minetest_config(dir);
  const auto recorded = config::Config::parse(config.preparation).root();
  EXPECT_EQ(recorded["distances"][0]["type"].as<std::string>(), "euclidean");
  EXPECT_EQ(recorded["preprocess"]["top_k"].as<int>(), 3);
  const auto first = data::prepare_dataset(config, quiet(true));
  EXPECT_EQ(first.characters, 1u);
  EXPECT_EQ(first.computed, 1u);
  EXPECT_EQ(first.reused, 0u);
  EXPECT_TRUE(first.excluded.empty());
  const auto partial = dir / "out/minetest.h5.partial/character.h5";
  ASSERT_TRUE(std::filesystem::exists(partial));
  const auto written = data::read_dataset(dir / "out/minetest.h5");

  // As after a kill between the per-character files and the merge: output gone, partial kept.
  std::filesystem::remove(dir / "out/minetest.h5");
  const auto second = data::prepare_dataset(config, quiet(false));
  EXPECT_EQ(second.computed, 0u);
  EXPECT_EQ(second.reused, 1u);
  const auto reread = data::read_dataset(dir / "out/minetest.h5");
  ASSERT_EQ(reread.characters.size(), 1u);
  EXPECT_EQ(reread.characters[0].V, written.characters[0].V);
  EXPECT_EQ(reread.characters[0].distances.at("euclidean").D,
            written.characters[0].distances.at("euclidean").D);
  EXPECT_EQ(reread.characters[0].licence, "CC-BY-SA-3.0");
  EXPECT_EQ(reread.characters[0].skeleton, "minetest_player");
  EXPECT_FALSE(std::filesystem::exists(dir / "out/minetest.h5.partial"))
      << "removed after the merge";

  // A partial file made with another preprocessing config is not reused.
  data::prepare_dataset(config, quiet(true));
  const auto changed =
      data::prepare_dataset(minetest_config(dir, {"preprocess.top_k=2"}), quiet(false));
  EXPECT_EQ(changed.computed, 1u);
  EXPECT_EQ(changed.reused, 0u);
  EXPECT_EQ(data::read_dataset(dir / "out/minetest.h5")
                .characters[0]
                .distances.at("euclidean")
                .topk_index.cols(),
            2);
}

TEST(Prepare, FailuresAreCollectedNotFatal) {
  TempDir dir;
  dir.write("broken/bad.b3d", "not a b3d file");
  // A rig without skin lines reads, but cannot be preprocessed (no weights to learn).
  const auto player = testing::minetest_player();
  geometry::write_obj(dir / "broken/unskinned.obj", player.character.mesh);
  geometry::write_rig(dir / "broken/unskinned_rig.txt", player.character.skeleton, {});
  const auto config =
      minetest_config(dir, {"sources=[{type: folder, path: " + (dir / "broken").string() +
                            "}, {type: folder, path: " + testing::kMinetestModels + "}]"});
  const auto report = data::prepare_dataset(config, quiet(false));
  EXPECT_EQ(report.characters, 1u);
  ASSERT_EQ(report.excluded.size(), 2u);
  EXPECT_EQ(report.excluded[0].path, "bad.b3d");
  EXPECT_EQ(report.excluded[1].path, "unskinned.obj");
  EXPECT_NE(report.excluded[1].reason.find("no skin weights"), std::string::npos)
      << report.excluded[1].reason;
  const auto d = data::read_dataset(dir / "out/minetest.h5");
  EXPECT_EQ(d.excluded.size(), 2u);
  EXPECT_EQ(d.characters.at(0).name, "character");
}

TEST(Prepare, ConfigErrorsComeBeforeAnyWork) {
  TempDir dir;
  testing::expect_error<ConfigError>([&] { minetest_config(dir, {"preprocess.max_vertices=10"}); },
                                     {"preprocess.max_vertices", "must be ≥ min_vertices"});
  testing::expect_error<ConfigError>(
      [&] { minetest_config(dir, {"distances=[{type: euclidean}, {type: euclidean}]"}); },
      {"listed twice"});
  testing::expect_error<ConfigError>([&] { minetest_config(dir, {"sources.0.pathh=x"}); },
                                     {"pathh", "did you mean 'path'"});
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

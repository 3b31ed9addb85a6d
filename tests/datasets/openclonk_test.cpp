// The `openclonk` builder (datasets/openclonk/openclonk.hpp) on the bundled real group
// Chippie.ocd (openclonk-data, CC-BY-3.0; datasets/openclonk/bundled/LICENSE.md): names, the
// character, exclusions of broken groups and static meshes, options. The installed package is
// read by tests/packages/openclonk_package_test.cpp.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "datasets/byte_reader.hpp"
#include "datasets/openclonk/openclonk.hpp"
#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "tests/test_util.hpp"

namespace skinlab::datasets {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

const std::string kChippie = SKINLAB_SOURCE_DIR "/datasets/openclonk/bundled/Chippie.ocd";

OpenClonkBuilder::Options chippie_options(const std::string& path) {
  OpenClonkBuilder::Options o;
  o.path = path;
  o.licence = "CC-BY-3.0";
  o.attribution = "The OpenClonk Team";
  return o;
}

TEST(OpenClonk, CharacterNames) {
  EXPECT_EQ(OpenClonkBuilder::character_name("Objects.ocd/Clonk.ocd/Graphics.mesh"), "openclonk.Objects.Clonk");
  EXPECT_EQ(OpenClonkBuilder::character_name("Objects.ocd/Clonk.ocd/GraphicsFarmer.mesh"),
            "openclonk.Objects.Clonk.Farmer");
  EXPECT_EQ(OpenClonkBuilder::character_name("Objects.ocd/Animals.ocd/Wipf.ocd/Graphics.mesh"),
            "openclonk.Objects.Animals.Wipf");
  EXPECT_EQ(OpenClonkBuilder::character_name("Arena.ocf/Hideout.ocs/Flag.ocd/Body.mesh"),
            "openclonk.Arena.Hideout.Flag.Body");
}

TEST(OpenClonk, ReadsTheBundledGroup) {
  std::vector<Excluded> excluded;
  const auto characters = OpenClonkBuilder(chippie_options(kChippie)).read(excluded);
  ASSERT_EQ(characters.size(), 1u);
  const SourceCharacter& c = characters[0];
  EXPECT_EQ(c.character.name, "openclonk.Chippie");
  EXPECT_EQ(c.source, "openclonk");
  EXPECT_EQ(c.path, "Chippie.ocd/Graphics.mesh");
  EXPECT_EQ(c.skeleton, "Chippie");
  EXPECT_EQ(c.licence, "CC-BY-3.0");
  EXPECT_EQ(c.attribution, "The OpenClonk Team");
  EXPECT_TRUE(c.up.isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_EQ(c.character.mesh.V.rows(), 209);
  EXPECT_EQ(c.character.skeleton.num_joints(), 13);  // 14 bones, an unweighted root subtree pruned
  const Eigen::VectorXd sums = c.character.weights * Eigen::VectorXd::Ones(c.character.weights.cols());
  EXPECT_LT((sums.array() - 1).abs().maxCoeff(), 1e-9);
  EXPECT_EQ(c.animations.size(), 1u);
  ASSERT_EQ(excluded.size(), 1u);
  EXPECT_EQ(excluded[0].source, "openclonk");
  EXPECT_EQ(excluded[0].path, "Chippie.ocd/Egg.ocd/Graphics.mesh");
  EXPECT_NE(excluded[0].reason.find("static mesh"), std::string::npos) << excluded[0].reason;
}

TEST(OpenClonk, ReadsADirectoryOfGroupsAndExcludesBrokenOnes) {
  testing::TempDir dir;
  std::filesystem::copy_file(kChippie, dir / "Chippie.ocd");
  const std::string packed = read_binary_file(kChippie);
  dir.write("Broken.ocd", packed.substr(0, 1000));
  dir.write("Music.ocg/Song.ogg", "not a mesh");  // an unpacked group, as Debian installs Music.ocg
  dir.write("Loose.ocd/Rock.mesh", "not a mesh either");
  OpenClonkBuilder::Options o = chippie_options(dir.path().string());
  o.exclude.emplace_back("Chippie.ocd/Egg.ocd/*", "an egg, not a character");
  std::vector<Excluded> excluded;
  const auto characters = OpenClonkBuilder(o).read(excluded);
  ASSERT_EQ(characters.size(), 1u);
  EXPECT_EQ(characters[0].character.name, "openclonk.Chippie");
  ASSERT_EQ(excluded.size(), 3u);
  std::sort(excluded.begin(), excluded.end(), [](const auto& a, const auto& b) { return a.path < b.path; });
  EXPECT_EQ(excluded[0].path, "Broken.ocd");
  EXPECT_NE(excluded[0].reason.find("Broken.ocd: truncated gzip stream"), std::string::npos) << excluded[0].reason;
  EXPECT_EQ(excluded[1].path, "Chippie.ocd/Egg.ocd/Graphics.mesh");
  EXPECT_NE(excluded[1].reason.find("excluded by the config (Chippie.ocd/Egg.ocd/*): an egg"), std::string::npos);
  EXPECT_EQ(excluded[2].path, "Loose.ocd/Rock.mesh");
  EXPECT_NE(excluded[2].reason.find("Loose.ocd/Rock.mesh: file header"), std::string::npos) << excluded[2].reason;
  testing::expect_error<IoError>(
      [&] { OpenClonkBuilder(chippie_options((dir / "absent").string())).read(excluded); },
      {"dataset 'openclonk'", "absent", "install openclonk-data"});
}

TEST(OpenClonk, OptionsAndRegistry) {
  const auto cfg = config::Config::parse(
      "type: openclonk\npath: " + kChippie +
      "\nlicence: CC-BY-3.0\nanimations: false\nexclude: {\"*/Egg.ocd/*\": an egg}\n"
      "credits: [{files: \"Chippie.ocd/*\", licence: CC-BY-3.0, attribution: someone}]\n");
  const OpenClonkBuilder::Options o = OpenClonkBuilder::Options::from(cfg.root());
  EXPECT_EQ(o.path, kChippie);
  EXPECT_FALSE(o.animations);
  ASSERT_EQ(o.exclude.size(), 1u);
  ASSERT_EQ(o.credits.size(), 1u);
  EXPECT_EQ(OpenClonkBuilder::Options::from(config::Config::parse("type: openclonk\n").root()).path,
            "/usr/share/games/openclonk");
  const auto builder = dataset_registry().create(cfg.root());
  std::vector<Excluded> excluded;
  const auto characters = builder->read(excluded);
  ASSERT_EQ(characters.size(), 1u);
  EXPECT_EQ(characters[0].attribution, "someone");
  EXPECT_TRUE(characters[0].animations.empty());
  testing::expect_error<ConfigError>(
      [&] { OpenClonkBuilder::Options::from(config::Config::parse("type: openclonk\nrepository: x/y\n").root()); },
      {"repository"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::datasets

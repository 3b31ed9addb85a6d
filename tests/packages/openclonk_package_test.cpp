// The `openclonk` builder on the installed Debian package openclonk-data, read as
// configs/datasets/openclonk.yaml reads it: the characters it keeps, their weights. Skipped
// when the package is not installed (scripts/setup --data installs it). Label `long`.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "datasets/openclonk/openclonk.hpp"
#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"

namespace skinlab::datasets {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

TEST(OpenClonkPackage, ReadsTheCharactersOfTheConfig) {
  if (!std::filesystem::exists("/usr/share/games/openclonk/Objects.ocd")) {
    GTEST_SKIP() << "openclonk-data is not installed";
  }
  const auto cfg = config::Config::load(SKINLAB_SOURCE_DIR "/configs/datasets/openclonk.yaml");
  const auto builder = dataset_registry().create(cfg.root()["sources"][0]);
  std::vector<Excluded> excluded;
  const auto characters = builder->read(excluded);
  std::vector<std::string> names;
  for (const auto& c : characters) {
    names.push_back(c.character.name);
    EXPECT_EQ(c.source, "openclonk");
    EXPECT_EQ(c.licence, "CC-BY-3.0");
    const auto& W = c.character.weights;
    ASSERT_EQ(W.rows(), c.character.mesh.V.rows()) << c.character.name;
    const Eigen::VectorXd sums = W * Eigen::VectorXd::Ones(W.cols());
    EXPECT_LT((sums.array() - 1).abs().maxCoeff(), 1e-9) << c.character.name;
    EXPECT_GE(W.coeffs().minCoeff(), 0.0) << c.character.name;
  }
  // The cleaning (min_bones 4) then drops the butterfly (3 bones, 8 vertices): 13 characters.
  EXPECT_EQ(names, (std::vector<std::string>{
                       "openclonk.Objects.Animals.Bat", "openclonk.Objects.Animals.Butterfly",
                       "openclonk.Objects.Animals.Chippie", "openclonk.Objects.Animals.Fish",
                       "openclonk.Objects.Animals.Mooq", "openclonk.Objects.Animals.Piranha",
                       "openclonk.Objects.Animals.Puka", "openclonk.Objects.Animals.Shark",
                       "openclonk.Objects.Animals.Squid", "openclonk.Objects.Animals.Wipf",
                       "openclonk.Objects.Clonk", "openclonk.Objects.Clonk.Alchemist",
                       "openclonk.Objects.Clonk.Farmer", "openclonk.Objects.Clonk.Steampunk"}));
  // Every other mesh is excluded with its reason: 131 by the config, and 5 static meshes by the
  // builder (the Chippie's egg, the lava core and its shell, the Zaphive, the gravestone).
  int by_config = 0;
  for (const auto& e : excluded) {
    EXPECT_FALSE(e.reason.empty()) << e.path;
    by_config += e.reason.rfind("excluded by the config", 0) == 0;
  }
  EXPECT_EQ(characters.size() + excluded.size(), 150u);
  EXPECT_EQ(by_config, 131);
  EXPECT_EQ(excluded.size() - by_config, 5u);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::datasets

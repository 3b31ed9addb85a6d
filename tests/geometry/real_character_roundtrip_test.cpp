// A real game character (Minetest's player, Debian package minetest-data, CC BY-SA 3.0) goes
// through the whole IO path: assimp import → normalise → OBJ + RigNet rig text → read back, with
// bit-identical mesh, skeleton and weights, and the same distances from every registered distance.

#include <gtest/gtest.h>

#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/distances/distance.hpp"
#include "framework/geometry/load_character.hpp"
#include "framework/geometry/normalize.hpp"
#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/rig_io.hpp"
#include "tests/test_util.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

const std::filesystem::path kPlayer =
    "/usr/share/games/minetest/games/minetest_game/mods/player_api/models/character.b3d";

TEST(RealCharacter, RoundTripsThroughObjAndRigText) {
  ASSERT_TRUE(std::filesystem::exists(kPlayer)) << kPlayer << " is missing; run scripts/setup";
  Character c = load_character(kPlayer);
  normalize(c);
  ASSERT_TRUE(c.has_weights());

  skinlab::testing::TempDir dir;
  write_obj(dir / "player.obj", c.mesh);
  write_rig(dir / "player_rig.txt", c.skeleton, c.weights);
  const Character back = load_character(dir / "player.obj", dir / "player_rig.txt");

  EXPECT_EQ(back.name, "player");
  EXPECT_EQ(back.mesh.V, c.mesh.V);
  EXPECT_EQ(back.mesh.F, c.mesh.F);
  EXPECT_EQ(back.skeleton.names, c.skeleton.names);
  EXPECT_EQ(back.skeleton.parents, c.skeleton.parents);
  EXPECT_EQ(back.skeleton.positions, c.skeleton.positions);
  EXPECT_EQ(Eigen::MatrixXd(back.weights), Eigen::MatrixXd(c.weights));

  for (const auto& key : distance_registry().keys()) {
    const auto distance =
        distance_registry().create(config::Config::parse("type: " + key).root());
    const Eigen::MatrixXd a = distance->compute(c.mesh, c.skeleton);
    EXPECT_EQ(a.rows(), c.mesh.num_vertices()) << key;
    EXPECT_EQ(a.cols(), static_cast<Eigen::Index>(c.skeleton.bones().size())) << key;
    EXPECT_TRUE(a.allFinite()) << key;
    EXPECT_GE(a.minCoeff(), 0.0) << key;
    EXPECT_EQ(distance->compute(back.mesh, back.skeleton), a) << key;
  }
}

TEST(RealCharacter, LoadCharacterErrors) {
  skinlab::testing::TempDir dir;
  skinlab::testing::expect_error<GeometryError>([&] { load_character(dir / "a.obj"); },
                                                {"a.obj: an OBJ mesh has no skeleton"});
  skinlab::testing::expect_error<GeometryError>(
      [&] { load_character(kPlayer, dir / "rig.txt"); },
      {"character.b3d: a rig file", "goes with an OBJ mesh"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

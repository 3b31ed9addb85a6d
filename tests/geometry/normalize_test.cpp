#include "framework/geometry/normalize.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>

#include "framework/geometry/import_character.hpp"
#include "tests/test_util.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

/// A box character standing along +Z (Z up): x ∈ [1, 3], y ∈ [−1, 0], z ∈ [2, 6]; joints at the
/// bottom and top of its axis.
Character z_up_box() {
  Character c;
  c.name = "box";
  c.mesh.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) {
    c.mesh.V.row(i) << (i & 1 ? 3 : 1), (i & 2 ? 0 : -1), (i & 4 ? 6 : 2);
  }
  c.mesh.F.resize(2, 3);
  c.mesh.F << 0, 1, 2, 4, 5, 6;
  c.skeleton.names = {"hips", "head"};
  c.skeleton.parents = {-1, 0};
  c.skeleton.positions.resize(2, 3);
  c.skeleton.positions << 2, -0.5, 2, 2, -0.5, 6;
  return c;
}

TEST(Normalize, ZUpInputBecomesYUpUnitHeightCentredOnTheFloor) {
  Character c = z_up_box();
  const Eigen::MatrixXd original = c.mesh.V;
  NormalizeOptions options;
  options.source_up = Eigen::Vector3d::UnitZ();
  const Similarity s = normalize(c, options);
  const Eigen::RowVector3d lo = c.mesh.V.colwise().minCoeff();
  const Eigen::RowVector3d hi = c.mesh.V.colwise().maxCoeff();
  EXPECT_NEAR(hi.y() - lo.y(), 1.0, 1e-12);    // height 1
  EXPECT_NEAR(lo.y(), 0.0, 1e-12);             // feet on the floor
  EXPECT_NEAR(lo.x() + hi.x(), 0.0, 1e-12);    // centred in x
  EXPECT_NEAR(lo.z() + hi.z(), 0.0, 1e-12);    // centred in z
  EXPECT_NEAR(s.scale, 0.25, 1e-12);
  // Blender's Z-up → Y-up: (x, y, z) ↦ (x, z, −y); the head joint is straight above the hips.
  const Eigen::Matrix3d expected = (Eigen::Matrix3d() << 1, 0, 0, 0, 0, 1, 0, -1, 0).finished();
  EXPECT_TRUE(s.rotation.isApprox(expected, 1e-12)) << s.rotation;
  EXPECT_LT(c.skeleton.positions.row(0).norm(), 1e-12);
  EXPECT_TRUE(c.skeleton.positions.row(1).isApprox(Eigen::RowVector3d(0, 1, 0), 1e-12));
  // The returned map is what was applied, and its inverse maps back.
  EXPECT_TRUE(s.apply(original).isApprox(c.mesh.V, 1e-12));
  EXPECT_TRUE(s.inverse().apply(c.mesh.V).isApprox(original, 1e-12));
}

TEST(Normalize, ApplyAfterInverseIsTheIdentity) {
  Similarity s;
  s.scale = 0.37;
  s.rotation = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  s.translation = Eigen::Vector3d(0.3, -4, 2);
  const Eigen::MatrixXd P = Eigen::MatrixXd::Random(20, 3) * 10;
  EXPECT_TRUE(s.inverse().apply(s.apply(P)).isApprox(P, 1e-12));
  EXPECT_TRUE(s.apply(s.inverse().apply(P)).isApprox(P, 1e-12));
  EXPECT_TRUE(s.after(s.inverse()).matrix().isApprox(Eigen::Matrix4d::Identity(), 1e-12));
  EXPECT_TRUE(s.inverse().matrix().isApprox(s.matrix().inverse(), 1e-12));
  // after() composes in application order.
  Similarity t;
  t.scale = 2;
  t.translation = Eigen::Vector3d(1, 1, 1);
  EXPECT_TRUE(t.after(s).apply(P).isApprox(t.apply(s.apply(P)), 1e-12));
}

TEST(Normalize, DownwardUpAxisTurnsAboutX) {
  Character c = z_up_box();
  NormalizeOptions options;
  options.source_up = -Eigen::Vector3d::UnitY();
  const Similarity s = normalize(c, options);
  EXPECT_TRUE((s.rotation * Eigen::Vector3d(0, -1, 0)).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_TRUE((s.rotation * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
  EXPECT_NEAR(s.scale, 1.0, 1e-12);  // the box is 1 unit deep in y
}

TEST(Normalize, FlatMeshIsAnError) {
  Character c = z_up_box();
  c.mesh.V.col(1).setConstant(2.0);
  skinlab::testing::expect_error<GeometryError>([&] { normalize(c); },
                                                {"box", "zero height"});
  NormalizeOptions zero;
  zero.source_up.setZero();
  skinlab::testing::expect_error<GeometryError>([&] { normalize(c, zero); }, {"box", "up axis"});
}

TEST(Normalize, MinetestPlayerIsScaledFrom17Units) {
  const std::filesystem::path file =
      "/usr/share/games/minetest/games/minetest_game/mods/player_api/models/character.b3d";
  ASSERT_TRUE(std::filesystem::exists(file)) << file << " is missing; run scripts/setup";
  Character c = import_character(file);
  const Eigen::MatrixXd original = c.mesh.V;
  const Similarity s = normalize(c);
  EXPECT_NEAR(s.scale, 1.0 / 17.0, 1e-6);
  EXPECT_TRUE(s.rotation.isIdentity());
  EXPECT_NEAR(c.mesh.V.col(1).maxCoeff(), 1.0, 1e-12);
  EXPECT_TRUE(s.inverse().apply(c.mesh.V).isApprox(original, 1e-12));
  EXPECT_NO_THROW(c.validate());
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

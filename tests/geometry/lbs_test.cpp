#include "framework/geometry/lbs.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/test_util.hpp"

namespace skinlab::geometry {
namespace {

/// Joints root (0,0,0) → child (0,1,0). Vertices: (0,0.5,0) on root, (0,2,0) on child, (1,1,0)
/// half and half.
struct TwoBones {
  Skeleton skeleton;
  Eigen::MatrixXd V;
  SparseWeights W;
  TwoBones() {
    skeleton.names = {"root", "child"};
    skeleton.parents = {-1, 0};
    skeleton.positions = (Eigen::MatrixXd(2, 3) << 0, 0, 0, 0, 1, 0).finished();
    V = (Eigen::MatrixXd(3, 3) << 0, 0.5, 0, 0, 2, 0, 1, 1, 0).finished();
    W.resize(3, 2);
    W.insert(0, 0) = 1;
    W.insert(1, 1) = 1;
    W.insert(2, 0) = 0.5;
    W.insert(2, 1) = 0.5;
    W.makeCompressed();
  }
};

Eigen::Matrix3d rot_z(double degrees) {
  return Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

TEST(Lbs, BendingTheChildByHand) {
  TwoBones r;
  // Child turns 90° about z at (0,1,0): (0,2,0) → (−1,1,0); (1,1,0) → child says (0,2,0),
  // root says (1,1,0), blended (0.5,1.5,0).
  const Eigen::MatrixXd P =
      lbs(r.V, r.W, forward_kinematics(r.skeleton, {Eigen::Matrix3d::Identity(), rot_z(90)}));
  const Eigen::MatrixXd expected =
      (Eigen::MatrixXd(3, 3) << 0, 0.5, 0, -1, 1, 0, 0.5, 1.5, 0).finished();
  EXPECT_TRUE(P.isApprox(expected, 1e-12)) << P;
}

TEST(Lbs, RootRotationCarriesTheChild) {
  TwoBones r;
  // Root turns 90° about z at the origin, child follows rigidly: (x, y) ↦ (−y, x) everywhere.
  const Eigen::MatrixXd P =
      lbs(r.V, r.W, forward_kinematics(r.skeleton, {rot_z(90), Eigen::Matrix3d::Identity()}));
  const Eigen::MatrixXd expected =
      (Eigen::MatrixXd(3, 3) << -0.5, 0, 0, -2, 0, 0, -1, 1, 0).finished();
  EXPECT_TRUE(P.isApprox(expected, 1e-12)) << P;
  // Root 90° then child −90°: the child's segment keeps its rest direction, translated.
  const auto T = forward_kinematics(r.skeleton, {rot_z(90), rot_z(-90)});
  EXPECT_TRUE((T[1] * Eigen::Vector3d(0, 2, 0)).isApprox(Eigen::Vector3d(-1, 1, 0), 1e-12));
}

TEST(Lbs, IdentityPoseAndExplicitTransforms) {
  TwoBones r;
  const auto T = forward_kinematics(r.skeleton, {Eigen::Matrix3d::Identity(),
                                                 Eigen::Matrix3d::Identity()});
  for (const auto& t : T) EXPECT_TRUE(t.matrix().isIdentity());
  EXPECT_EQ(lbs(r.V, r.W, T), r.V);
  // A translation of the child only: the shared vertex moves half way.
  std::vector<Eigen::Affine3d> shift(2, Eigen::Affine3d::Identity());
  shift[1] = Eigen::Translation3d(0, 0, 2);
  const Eigen::MatrixXd P = lbs(r.V, r.W, shift);
  EXPECT_TRUE(P.row(2).isApprox(Eigen::RowVector3d(1, 1, 1), 1e-12));
  EXPECT_TRUE(P.row(0).isApprox(r.V.row(0), 1e-12));
}

TEST(Lbs, ShapeMismatchIsAnError) {
  TwoBones r;
  skinlab::testing::expect_error<GeometryError>(
      [&] { lbs(r.V, r.W, {Eigen::Affine3d::Identity()}); }, {"lbs", "3×2", "3×1"});
  skinlab::testing::expect_error<GeometryError>(
      [&] { forward_kinematics(r.skeleton, {Eigen::Matrix3d::Identity()}); },
      {"1 rotations for 2 joints"});
}

TEST(Lbs, RandomPoseRotatesAboutAFractionOfJoints) {
  Skeleton s;
  for (int j = 0; j < 200; ++j) {
    s.names.push_back("j" + std::to_string(j));
    s.parents.push_back(j - 1);
  }
  s.positions = Eigen::MatrixXd::Random(200, 3);
  std::mt19937 a(7), b(7);
  const auto pose = random_pose(s, a);
  EXPECT_EQ(pose, random_pose(s, b));  // seeded: reproducible
  int rotated = 0;
  for (const auto& R : pose) {
    EXPECT_TRUE((R * R.transpose()).isIdentity(1e-12));
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    rotated += !R.isIdentity();
  }
  EXPECT_GT(rotated, 30);  // Binomial(200, 0.3): mean 60, sd 6.5
  EXPECT_LT(rotated, 90);
  std::mt19937 c(1);
  for (const auto& R : random_pose(s, c, 0.0)) EXPECT_TRUE(R.isIdentity());
}

}  // namespace
}  // namespace skinlab::geometry

#include "framework/geometry/lbs.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/test_util.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

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

Skeleton chain(int n) {
  Skeleton s;
  for (int j = 0; j < n; ++j) {
    s.names.push_back("j" + std::to_string(j));
    s.parents.push_back(j - 1);
  }
  s.positions = Eigen::MatrixXd::Random(n, 3);
  return s;
}

int count_rotated(const std::vector<Eigen::Matrix3d>& pose) {
  int rotated = 0;
  for (const auto& R : pose) rotated += !R.isIdentity();
  return rotated;
}

TEST(Lbs, RandomPoseRotatesAnExactFractionOfJoints) {
  const Skeleton s = chain(200);
  std::mt19937 a(7), b(7);
  const auto pose = random_pose(s, a);
  EXPECT_EQ(pose, random_pose(s, b));  // seeded: reproducible
  for (const auto& R : pose) {
    EXPECT_TRUE((R * R.transpose()).isIdentity(1e-12));
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  }
  EXPECT_EQ(count_rotated(pose), 60);  // round(0.3 · 200)
  // round(0.3 · 10) = 3 on every draw, and the chosen joints vary between draws.
  const Skeleton small = chain(10);
  std::mt19937 c(1);
  std::vector<int> times_chosen(10, 0);
  for (int trial = 0; trial < 200; ++trial) {
    const auto p = random_pose(small, c);
    EXPECT_EQ(count_rotated(p), 3);
    for (int j = 0; j < 10; ++j) times_chosen[j] += !p[j].isIdentity();
  }
  for (int j = 0; j < 10; ++j) EXPECT_GT(times_chosen[j], 30) << j;  // mean 60, sd 6.5
  for (const auto& R : random_pose(s, c, 0.0)) EXPECT_TRUE(R.isIdentity());
  EXPECT_EQ(count_rotated(random_pose(s, c, 1.0)), 200);
}

TEST(Lbs, RandomPoseAnglesFollowTheRequestedSpread) {
  // Rotation angles are |N(0, σ²)|: mean σ·√(2/π) and mean square σ².
  const Skeleton s = chain(1000);
  std::mt19937 rng(3);
  double sum = 0, sum_sq = 0;
  int n = 0;
  for (int trial = 0; trial < 10; ++trial) {
    for (const auto& R : random_pose(s, rng, 1.0, 25.0)) {
      const double degrees = Eigen::AngleAxisd(R).angle() * 180 / M_PI;
      sum += degrees, sum_sq += degrees * degrees, ++n;
    }
  }
  EXPECT_NEAR(sum / n, 25.0 * std::sqrt(2 / M_PI), 0.3);  // standard error ≈ 0.19
  EXPECT_NEAR(std::sqrt(sum_sq / n), 25.0, 0.3);
}

TEST(Lbs, RandomPoseRejectsBadArguments) {
  const Skeleton s = chain(3);
  std::mt19937 rng(0);
  skinlab::testing::expect_error<GeometryError>([&] { random_pose(s, rng, 1.5); },
                                                {"fraction must be in [0, 1]", "1.5"});
  skinlab::testing::expect_error<GeometryError>([&] { random_pose(s, rng, 0.3, -1); },
                                                {"sigma_degrees"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

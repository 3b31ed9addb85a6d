// Dual quaternion skinning against hand-computed poses: a blend of rotations about one joint is
// a rotation about it (rigid: distances to the joint kept, where linear blending shrinks them),
// blends take the short way round, one influence is the joint's own rigid motion, and bad input
// is an error naming the joint or vertex.
#include "framework/geometry/dqs.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "framework/geometry/lbs.hpp"
#include "tests/test_util.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;

/// Joints root (0,0,0) → child (0,1,0).
Skeleton two_joints() {
  Skeleton s;
  s.names = {"root", "child"};
  s.parents = {-1, 0};
  s.positions = (Eigen::MatrixXd(2, 3) << 0, 0, 0, 0, 1, 0).finished();
  return s;
}

Eigen::Matrix3d rot_z(double degrees) {
  return Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

SparseWeights weights(const std::vector<std::pair<double, double>>& rows) {
  SparseWeights W(static_cast<Eigen::Index>(rows.size()), 2);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].first > 0) W.insert(static_cast<Eigen::Index>(i), 0) = rows[i].first;
    if (rows[i].second > 0) W.insert(static_cast<Eigen::Index>(i), 1) = rows[i].second;
  }
  W.makeCompressed();
  return W;
}

TEST(Dqs, BendingTheChildByHand) {
  // Child turns 90° about z at (0,1,0). (1,1,0), half on each joint, turns 45° about the child
  // joint: (1 + cos 45°… i.e. (cos 45°, 1 + sin 45°, 0)), where LBS gives (0.5, 1.5, 0).
  const Eigen::MatrixXd V = (Eigen::MatrixXd(3, 3) << 0, 0.5, 0, 0, 2, 0, 1, 1, 0).finished();
  const SparseWeights W = weights({{1, 0}, {0, 1}, {0.5, 0.5}});
  const auto T = forward_kinematics(two_joints(), {Eigen::Matrix3d::Identity(), rot_z(90)});
  const double h = std::sqrt(0.5);
  const Eigen::MatrixXd expected =
      (Eigen::MatrixXd(3, 3) << 0, 0.5, 0, -1, 1, 0, h, 1 + h, 0).finished();
  EXPECT_TRUE(dqs(V, W, T).isApprox(expected, 1e-12)) << dqs(V, W, T);
  EXPECT_TRUE(dqs(V, W, forward_kinematics(two_joints(), {Eigen::Matrix3d::Identity(),
                                                          Eigen::Matrix3d::Identity()}))
                  .isApprox(V, 1e-15));
}

TEST(Dqs, ARotationAboutOneJointIsRigidWhereLbsShrinks) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1), w(0.05, 0.95);
  const int n = 50;
  Eigen::MatrixXd V(n, 3);
  std::vector<std::pair<double, double>> rows;
  for (int i = 0; i < n; ++i) {
    V.row(i) << u(rng), 1 + u(rng), u(rng);
    const double a = w(rng);
    rows.emplace_back(a, 1 - a);
  }
  const SparseWeights W = weights(rows);
  const Eigen::Vector3d joint(0, 1, 0);
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
  const auto T = forward_kinematics(two_joints(), {Eigen::Matrix3d::Identity(), turn});
  const Eigen::MatrixXd D = dqs(V, W, T), L = lbs(V, W, T);
  double lbs_shrink = 0;
  for (int i = 0; i < n; ++i) {
    const double rest = (V.row(i).transpose() - joint).norm();
    EXPECT_NEAR((D.row(i).transpose() - joint).norm(), rest, 1e-12) << i;
    lbs_shrink = std::max(lbs_shrink, rest - (L.row(i).transpose() - joint).norm());
  }
  EXPECT_GT(lbs_shrink, 0.1);  // the volume loss DQS avoids
}

TEST(Dqs, BlendsTakeTheShortWayRound) {
  // The child turns 200° = −160°; halfway is −80°, not +100°, whichever sign the child's
  // quaternion came with.
  const Eigen::MatrixXd V = (Eigen::MatrixXd(1, 3) << 1, 1, 0).finished();
  const SparseWeights W = weights({{0.5, 0.5}});
  for (const double degrees : {200.0, -160.0}) {
    const auto T = forward_kinematics(two_joints(), {Eigen::Matrix3d::Identity(), rot_z(degrees)});
    const double a = -80 * M_PI / 180;
    EXPECT_TRUE(dqs(V, W, T).row(0).isApprox(Eigen::RowVector3d(std::cos(a), 1 + std::sin(a), 0),
                                             1e-12))
        << degrees << ": " << dqs(V, W, T);
  }
}

TEST(Dqs, OneInfluenceIsTheJointsRigidMotionAndBadInputIsAnError) {
  const Eigen::MatrixXd V = (Eigen::MatrixXd(2, 3) << 0.3, 2, -1, 2, 0.5, 0.1).finished();
  const SparseWeights W = weights({{0, 2}, {1, 0}});  // unnormalised rows are fine
  Eigen::Affine3d moved = Eigen::Affine3d::Identity();
  moved.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0, 1, 1).normalized()));
  moved.pretranslate(Eigen::Vector3d(0.5, -2, 3));
  const std::vector<Eigen::Affine3d> T{Eigen::Affine3d::Identity(), moved};
  EXPECT_TRUE(dqs(V, W, T).row(0).isApprox((moved * Eigen::Vector3d(V.row(0).transpose())).transpose(), 1e-12));
  EXPECT_TRUE(dqs(V, W, T).row(1).isApprox(V.row(1), 1e-15));

  Eigen::Affine3d scaled = moved;
  scaled.scale(1.5);
  expect_error<GeometryError>([&] { dqs(V, W, {T[0], scaled}); }, {"joint 1", "not rigid"});
  expect_error<GeometryError>([&] { dqs(V, weights({{0, 1}, {0, 0}}), T); },
                              {"vertex 1", "no weight"});
  expect_error<GeometryError>([&] { dqs(V, W, {T[0]}); }, {"2×2", "#V×#J = 2×1"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

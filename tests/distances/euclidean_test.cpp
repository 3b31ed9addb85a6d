// `euclidean` distance: hand-computed point–segment distances, helper bones, options.

#include <gtest/gtest.h>

#include <cmath>

#include "framework/core/registry.hpp"
#include "framework/distances/euclidean.hpp"
#include "framework/geometry/closest_point_on_segment.hpp"
#include "tests/distances/shapes.hpp"
#include "tests/test_util.hpp"

namespace skinlab::distances {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using geometry::point_segment_distance;

std::shared_ptr<Distance> make(const std::string& yaml) {
  return distance_registry().create(config::Config::parse(yaml, "test.yaml").root());
}

TEST(EuclideanDistance, PointSegmentByHand) {
  const Eigen::Vector3d a(0, 0, 0), b(2, 0, 0);
  EXPECT_DOUBLE_EQ(point_segment_distance({1, 1, 0}, a, b), 1.0);              // above the middle
  EXPECT_DOUBLE_EQ(point_segment_distance({-1, 0, 0}, a, b), 1.0);             // before the start
  EXPECT_DOUBLE_EQ(point_segment_distance({3, 4, 0}, a, b), std::sqrt(17.0));  // past the end
  EXPECT_DOUBLE_EQ(point_segment_distance({0.5, 0, 0}, a, b), 0.0);            // on the bone
  EXPECT_DOUBLE_EQ(point_segment_distance({1, 2, 2}, a, b), std::sqrt(8.0));
  // A zero-length (helper) bone is a point.
  EXPECT_DOUBLE_EQ(point_segment_distance({1, 2, 2}, b, b), 3.0);
}

TEST(EuclideanDistance, MatrixWithHelperBoneByHand) {
  geometry::Mesh mesh;
  mesh.V.resize(3, 3);
  mesh.V << 1, 1, 0,  //
      -1, 0, 0,       //
      3, 4, 0;
  mesh.F.resize(1, 3);
  mesh.F << 0, 1, 2;
  Eigen::MatrixXd joints(2, 3);
  joints << 0, 0, 0, 2, 0, 0;
  const auto skeleton = testing::chain(joints);  // bones: j0 -> j1, helper at j1
  ASSERT_EQ(skeleton.bones().size(), 2u);
  const Eigen::MatrixXd D = make("{type: euclidean}")->compute(mesh, skeleton);
  ASSERT_EQ(D.rows(), 3);
  ASSERT_EQ(D.cols(), 2);
  EXPECT_DOUBLE_EQ(D(0, 0), 1.0);
  EXPECT_DOUBLE_EQ(D(1, 0), 1.0);
  EXPECT_DOUBLE_EQ(D(2, 0), std::sqrt(17.0));
  EXPECT_DOUBLE_EQ(D(0, 1), std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(D(1, 1), 3.0);
  EXPECT_DOUBLE_EQ(D(2, 1), std::sqrt(17.0));
}

TEST(EuclideanDistance, OneJointSkeletonIsOneHelperBone) {
  const auto mesh = testing::MeshBuilder().box({0, 0, 0}, {1, 1, 1}, 2).build();
  Eigen::MatrixXd joint(1, 3);
  joint << 0.5, 0.5, 0.5;
  const Eigen::MatrixXd D = make("{type: euclidean}")->compute(mesh, testing::chain(joint));
  ASSERT_EQ(D.cols(), 1);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    EXPECT_DOUBLE_EQ(D(v, 0), (mesh.V.row(v) - joint.row(0)).norm());
  }
}

TEST(EuclideanDistance, UnknownOptionIsAnError) {
  expect_error<ConfigError>(
      [] { make("{type: euclidean, resolution: 88}"); },
      {"test.yaml:1", "resolution", "unknown field of distance 'euclidean'", "known fields: type"});
}

TEST(EuclideanDistance, InvalidMeshIsAGeometryError) {
  geometry::Mesh mesh;
  mesh.V = Eigen::MatrixXd::Zero(3, 3);
  mesh.F.resize(1, 3);
  mesh.F << 0, 1, 5;
  Eigen::MatrixXd joint = Eigen::MatrixXd::Zero(1, 3);
  expect_error<geometry::GeometryError>(
      [&] { make("{type: euclidean}")->compute(mesh, testing::chain(joint)); },
      {"euclidean distance", "face 0", "vertex 5"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::distances

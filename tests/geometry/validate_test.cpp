// Every bad-input case of Mesh, Skeleton and weight validation, with its message.

#include <gtest/gtest.h>

#include <limits>

#include "framework/geometry/skin_weights.hpp"
#include "tests/test_util.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;

Mesh triangle() {
  Mesh m;
  m.V.resize(3, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  return m;
}

/// root -> spine -> {arm, leg}
Skeleton four_joints() {
  Skeleton s;
  s.names = {"root", "spine", "arm", "leg"};
  s.positions.resize(4, 3);
  s.positions << 0, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0;
  s.parents = {-1, 0, 1, 1};
  return s;
}

TEST(MeshValidate, AcceptsAGoodMesh) { EXPECT_NO_THROW(triangle().validate("tri")); }

TEST(MeshValidate, Rejects) {
  Mesh empty;
  expect_error<GeometryError>([&] { empty.validate("a.obj"); }, {"a.obj: mesh has no vertices"});
  Mesh no_faces = triangle();
  no_faces.F.resize(0, 3);
  expect_error<GeometryError>([&] { no_faces.validate("a.obj"); }, {"mesh has no faces"});
  Mesh nan = triangle();
  nan.V(1, 2) = std::numeric_limits<double>::quiet_NaN();
  expect_error<GeometryError>([&] { nan.validate("a.obj"); }, {"vertex 1 has a non-finite coordinate"});
  Mesh out_of_range = triangle();
  out_of_range.F(0, 2) = 3;
  expect_error<GeometryError>([&] { out_of_range.validate("a.obj"); },
                              {"face 0 refers to vertex 3, but the mesh has 3 vertices"});
  Mesh negative = triangle();
  negative.F(0, 0) = -1;
  expect_error<GeometryError>([&] { negative.validate("a.obj"); }, {"face 0 refers to vertex -1"});
  Mesh degenerate = triangle();
  degenerate.V.row(2) = degenerate.V.row(1);
  expect_error<GeometryError>([&] { degenerate.validate("a.obj"); },
                              {"every face of the mesh is degenerate"});
  Mesh quads = triangle();
  quads.F.resize(1, 4);
  quads.F << 0, 1, 2, 0;
  expect_error<GeometryError>([&] { quads.validate("a.obj"); }, {"#F×3"});
}

TEST(SkeletonValidate, BonesInRigNetOrderWithLeafHelpers) {
  const Skeleton s = four_joints();
  ASSERT_NO_THROW(s.validate("s"));
  const auto bones = s.bones();
  // root->spine, spine->arm, arm(helper), spine->leg, leg(helper)
  ASSERT_EQ(bones.size(), 5u);
  EXPECT_EQ(bones[0].start, 0);
  EXPECT_EQ(bones[0].end, 1);
  EXPECT_EQ(bones[1].end, 2);
  EXPECT_TRUE(bones[2].helper);
  EXPECT_EQ(bones[2].start, 2);
  EXPECT_EQ(bones[2].end, 2);
  EXPECT_EQ(bones[3].end, 3);
  EXPECT_TRUE(bones[4].helper);
  const Eigen::MatrixXd seg = s.bone_segments();
  EXPECT_EQ(seg.rows(), 5);
  EXPECT_TRUE(seg.row(2).head<3>().isApprox(seg.row(2).tail<3>()));
  EXPECT_EQ(s.root(), 0);
  EXPECT_EQ(s.find("arm"), 2);
  EXPECT_EQ(s.find("tail"), -1);

  Skeleton single;
  single.names = {"only"};
  single.positions = Eigen::MatrixXd::Zero(1, 3);
  single.parents = {-1};
  ASSERT_EQ(single.bones().size(), 1u);
  EXPECT_TRUE(single.bones()[0].helper);
}

TEST(SkeletonValidate, Rejects) {
  Skeleton none;
  expect_error<GeometryError>([&] { none.validate("r.txt"); }, {"r.txt: skeleton has no joints"});
  Skeleton two_roots = four_joints();
  two_roots.parents[3] = -1;
  expect_error<GeometryError>([&] { two_roots.validate("r.txt"); },
                              {"2 roots: 'root' and 'leg'"});
  Skeleton cycle = four_joints();
  cycle.parents = {-1, 3, 1, 2};  // spine -> leg -> arm -> spine
  expect_error<GeometryError>([&] { cycle.validate("r.txt"); }, {"cycle", "'spine'", "'leg'", "'arm'"});
  Skeleton rootless = four_joints();
  rootless.parents[0] = 1;
  expect_error<GeometryError>([&] { rootless.validate("r.txt"); }, {"no root joint"});
  Skeleton duplicate = four_joints();
  duplicate.names[3] = "arm";
  expect_error<GeometryError>([&] { duplicate.validate("r.txt"); },
                              {"duplicate joint name 'arm' (joints 2 and 3)"});
  Skeleton bad_parent = four_joints();
  bad_parent.parents[2] = 9;
  expect_error<GeometryError>([&] { bad_parent.validate("r.txt"); },
                              {"joint 'arm' has an invalid parent index 9"});
  Skeleton nan = four_joints();
  nan.positions(1, 0) = std::numeric_limits<double>::infinity();
  expect_error<GeometryError>([&] { nan.validate("r.txt"); }, {"joint 'spine' has a non-finite position"});
  expect_error<GeometryError>(
      [&] {
        Skeleton::from_parent_names({"a", "b"}, Eigen::MatrixXd::Zero(2, 3), {"", "c"}, "r.txt");
      },
      {"r.txt: joint 'b' has unknown parent 'c'"});
}

SparseWeights weights_from(const Eigen::MatrixXd& dense) {
  return dense.sparseView();
}

TEST(WeightsValidate, AcceptsRenormalisesAndRejects) {
  const Skeleton s = four_joints();
  Eigen::MatrixXd good(3, 4);
  good << 1, 0, 0, 0, 0, 0.5, 0.5, 0, 0, 0, 0, 1;
  SparseWeights w = weights_from(good);
  EXPECT_NO_THROW(check_weights(w, 3, s, "w"));

  Eigen::MatrixXd off = good;
  off(1, 2) = 0.7;  // row sums to 1.2
  SparseWeights bad_sum = weights_from(off);
  expect_error<GeometryError>([&] { check_weights(bad_sum, 3, s, "w.txt"); },
                              {"w.txt: vertex 1: weights sum to 1.2", "renormalising is an option"});
  WeightCheck renorm;
  renorm.renormalise = true;
  check_weights(bad_sum, 3, s, "w.txt", renorm);
  EXPECT_NEAR(bad_sum.coeff(1, 1), 0.5 / 1.2, 1e-12);
  EXPECT_NEAR(bad_sum.coeff(1, 2), 0.7 / 1.2, 1e-12);

  Eigen::MatrixXd negative = good;
  negative(0, 1) = -0.25;
  negative(0, 0) = 1.25;
  SparseWeights neg = weights_from(negative);
  expect_error<GeometryError>([&] { check_weights(neg, 3, s, "w.txt", renorm); },
                              {"vertex 0, joint 'spine': negative weight -0.25"});

  Eigen::MatrixXd empty_row = good;
  empty_row.row(2).setZero();
  SparseWeights empty = weights_from(empty_row);
  expect_error<GeometryError>([&] { check_weights(empty, 3, s, "w.txt", renorm); },
                              {"vertex 2 has no weight"});

  SparseWeights wrong_shape = weights_from(Eigen::MatrixXd::Identity(3, 3));
  expect_error<GeometryError>([&] { check_weights(wrong_shape, 3, s, "w.txt"); },
                              {"weights are 3×3, expected #V×#J = 3×4"});

  Eigen::MatrixXd nan = good;
  nan(0, 0) = std::numeric_limits<double>::quiet_NaN();
  SparseWeights not_finite = weights_from(nan);
  expect_error<GeometryError>([&] { check_weights(not_finite, 3, s, "w.txt"); },
                              {"vertex 0, joint 'root': weight is not finite"});
}

TEST(CharacterValidate, ChecksAllParts) {
  Character c;
  c.name = "hero";
  c.mesh = triangle();
  c.skeleton = four_joints();
  EXPECT_NO_THROW(c.validate());  // no weights is fine
  c.weights = weights_from(Eigen::MatrixXd::Identity(3, 4));
  EXPECT_NO_THROW(c.validate());
  c.skeleton.parents[0] = 2;
  expect_error<GeometryError>([&] { c.validate(); }, {"hero: "});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

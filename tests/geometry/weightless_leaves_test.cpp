// drop_weightless_leaves: the other skeleton-end convention, removing weightless end joints.

#include <gtest/gtest.h>

#include "framework/geometry/weightless_leaves.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

/// root -> arm -> hand -> hand_end -> hand_end2 and root -> head, one vertex per weighted joint.
Character rig(bool head_weighted) {
  Character c;
  c.name = "rig";
  c.mesh.V = Eigen::MatrixXd::Random(3, 3);
  c.mesh.F = Eigen::MatrixXi(1, 3);
  c.mesh.F << 0, 1, 2;
  Eigen::MatrixXd p(6, 3);
  p << 0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 4, 0, 0, 0, 1, 0;
  c.skeleton = Skeleton::from_parent_names({"root", "arm", "hand", "hand_end", "hand_end2", "head"},
                                           p, {"", "root", "arm", "hand", "hand_end", "root"},
                                           "rig");
  c.weights.resize(3, 6);
  c.weights.insert(0, 1) = 1.0;                   // arm
  c.weights.insert(1, 2) = 1.0;                   // hand
  c.weights.insert(2, head_weighted ? 5 : 0) = 1.0;  // head, or the root
  c.weights.makeCompressed();
  return c;
}

TEST(DropWeightlessLeaves, RemovesChainsOfWeightlessEndJoints) {
  Character c = rig(true);
  c.skeleton.leaf_tips = c.skeleton.positions;
  EXPECT_EQ(drop_weightless_leaves(c), (std::vector<int>{0, 1, 2, 5}));  // hand_end2, hand_end go
  EXPECT_EQ(c.skeleton.names, (std::vector<std::string>{"root", "arm", "hand", "head"}));
  EXPECT_EQ(c.skeleton.parents, (std::vector<int>{-1, 0, 1, 0}));
  EXPECT_TRUE(c.skeleton.positions.row(3).isApprox(Eigen::RowVector3d(0, 1, 0)));
  EXPECT_EQ(c.skeleton.leaf_tips.rows(), 4);
  ASSERT_EQ(c.weights.cols(), 4);
  EXPECT_EQ(c.weights.coeff(1, 2), 1.0);  // hand keeps its column, re-indexed
  EXPECT_EQ(c.weights.coeff(2, 3), 1.0);  // head moved from column 5 to 3
  c.validate();
  EXPECT_EQ(drop_weightless_leaves(c).size(), 4u);  // every leaf now carries weight
}

TEST(DropWeightlessLeaves, WeightlessLeafBesideWeightedOnesGoesTooButNeverTheRoot) {
  Character c = rig(false);  // head has no weight: it goes as well
  EXPECT_EQ(drop_weightless_leaves(c), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(c.skeleton.names, (std::vector<std::string>{"root", "arm", "hand"}));
  Character single;
  single.mesh = c.mesh;
  single.skeleton = Skeleton::from_parent_names({"root"}, Eigen::MatrixXd::Zero(1, 3), {""}, "s");
  single.weights.resize(3, 1);
  EXPECT_EQ(drop_weightless_leaves(single), std::vector<int>{0});
}

// Any leaves by a predicate: a chain goes whole, a removable joint above a kept one stays, and
// weight on a removed joint moves to its nearest kept ancestor; a rig without weights keeps none.
TEST(DropLeaves, RemovesEndsThePredicateNamesAndMovesTheirWeightUp) {
  Character c = rig(true);
  // hand_end2, hand_end and arm are removable; arm has a kept child (hand), so it stays
  EXPECT_EQ(drop_leaves(c, [](int j) { return j == 1 || j == 3 || j == 4; }),
            (std::vector<int>{0, 1, 2, 5}));
  EXPECT_EQ(c.skeleton.parents, (std::vector<int>{-1, 0, 1, 0}));
  Character weighted = rig(true);
  weighted.weights.coeffRef(1, 2) = 0.0;
  weighted.weights.coeffRef(1, 4) = 1.0;  // the vertex of hand now on hand_end2
  drop_leaves(weighted, [](int j) { return j >= 3 && j <= 4; });
  EXPECT_EQ(weighted.weights.coeff(1, 2), 1.0) << "hand_end2's weight moves to hand";
  Character bare = rig(true);
  bare.weights.resize(0, 0);
  EXPECT_EQ(drop_leaves(bare, [](int j) { return j == 5; }), (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(bare.weights.size(), 0);
  EXPECT_EQ(drop_leaves(bare, [](int) { return false; }).size(), 5u);
}

// Another method's weights on the end joints the truth drops go to the nearest kept ancestor.
TEST(OntoKeptJoints, MovesWeightOfRemovedJointsToTheirNearestKeptAncestor) {
  Character truth = rig(true);
  const std::vector<int> parents = truth.skeleton.parents;
  const std::vector<int> kept = drop_weightless_leaves(truth);  // root, arm, hand, head
  SparseWeights other(3, 6);
  other.insert(0, 4) = 0.5;  // hand_end2 -> hand
  other.insert(0, 3) = 0.2;  // hand_end -> hand
  other.insert(0, 1) = 0.3;  // arm stays arm
  other.insert(1, 2) = 1.0;  // hand
  other.insert(2, 5) = 1.0;  // head, re-indexed 5 -> 3
  other.makeCompressed();
  const SparseWeights mapped = onto_kept_joints(other, parents, kept);
  ASSERT_EQ(mapped.cols(), 4);
  EXPECT_DOUBLE_EQ(mapped.coeff(0, 2), 0.7);
  EXPECT_DOUBLE_EQ(mapped.coeff(0, 1), 0.3);
  EXPECT_DOUBLE_EQ(mapped.coeff(1, 2), 1.0);
  EXPECT_DOUBLE_EQ(mapped.coeff(2, 3), 1.0);
  EXPECT_EQ(mapped.nonZeros(), 4);
  EXPECT_THROW(onto_kept_joints(SparseWeights(3, 5), parents, kept), GeometryError);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

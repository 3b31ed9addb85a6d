// `dominant_joint`: the artist's dominant joint found, and leaf-dominated vertices given to the
// leaf's parent, counted by hand on the two-joint arm.

#include <gtest/gtest.h>

#include <cmath>

#include "framework/eval/dominant_joint.hpp"
#include "tests/eval/eval_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::eval {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::weights;

TEST(DominantJoint, CountsAgreementAndLeafToParentByHand) {
  const auto arm = testing::two_joint_arm();  // bone 0 moves with the root, bone 1 (helper) the child
  const auto metric = testing::make_metric("{type: dominant_joint, prune: 0}");
  // Artist: vertex 0 → root, vertices 1 and 2 → the child (a leaf, whose parent is the root).
  const torch::Tensor truth = weights({{0.9, 0.1}, {0.2, 0.8}, {0.0, 1.0}});
  // Prediction: vertex 0 right, vertex 1 given to the parent, vertex 2 right.
  const torch::Tensor pred = weights({{0.6, 0.4}, {0.7, 0.3}, {0.4, 0.6}});
  const auto v = (*metric)({pred, truth, &arm});
  EXPECT_DOUBLE_EQ(v.at("dominant_joint"), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(v.at("leaf_to_parent"), 1.0 / 2.0);
  EXPECT_EQ(metric->names(), (std::vector<std::string>{"dominant_joint", "leaf_to_parent"}));
}

TEST(DominantJoint, NoLeafDominatedVertexIsUndefinedNotZero) {
  const auto arm = testing::two_joint_arm();
  const auto metric = testing::make_metric("{type: dominant_joint}");
  const torch::Tensor truth = weights({{1, 0}, {0.6, 0.4}, {1, 0}});
  const auto v = (*metric)({truth, truth, &arm});
  EXPECT_DOUBLE_EQ(v.at("dominant_joint"), 1.0);
  EXPECT_TRUE(std::isnan(v.at("leaf_to_parent")));
}

TEST(DominantJoint, BonesOfOneJointAddUp) {
  // Joint 1 of a branching skeleton starts two bones; their weights add before the argmax.
  data::PreparedCharacter c = testing::two_joint_arm();
  c.joint_names = {"root", "spine", "a", "b"};
  c.parents = {-1, 0, 1, 1};
  c.joints = data::RowMatrixXd::Random(4, 3);
  c.bones = data::RowMatrixXi(5, 2);
  c.bones << 0, 1, 1, 2, 1, 3, 2, 2, 3, 3;
  const auto metric = testing::make_metric("{type: dominant_joint}");
  const torch::Tensor truth = weights({{0, 1, 0, 0, 0}, {0, 0, 0, 1, 0}, {0, 0, 0, 0, 1}});
  // Vertex 0: spine by 0.3 + 0.3 against the root's 0.4; vertex 1 (leaf a) given to the spine.
  const torch::Tensor pred =
      weights({{0.4, 0.3, 0.3, 0, 0}, {0, 0.5, 0.2, 0.3, 0}, {0, 0, 0, 0, 1}});
  const auto v = (*metric)({pred, truth, &c});
  EXPECT_DOUBLE_EQ(v.at("dominant_joint"), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(v.at("leaf_to_parent"), 1.0 / 2.0);
}

TEST(DominantJoint, JudgesThePrunedPrediction) {
  // Joint "a" starts two bones of 0.25 each (0.5 together) against the root's one bone of 0.26.
  data::PreparedCharacter c = testing::two_joint_arm();
  c.joint_names = {"root", "a", "b", "d"};
  c.parents = {-1, 0, 1, 1};
  c.joints = data::RowMatrixXd::Random(4, 3);
  c.bones = data::RowMatrixXi(5, 2);
  c.bones << 0, 1, 1, 2, 1, 3, 2, 2, 3, 3;
  c.V = c.V.topRows(1).eval();  // one vertex
  const torch::Tensor truth = weights({{0, 1, 0, 0, 0}});
  const torch::Tensor pred = weights({{0.26, 0.25, 0.25, 0.24, 0}});
  // Raw, a is dominant (right); pruned at 0.99 × the row maximum only the root's bone is left.
  EXPECT_DOUBLE_EQ((*testing::make_metric("{type: dominant_joint, prune: 0}"))({pred, truth, &c})
                       .at("dominant_joint"),
                   1.0);
  EXPECT_DOUBLE_EQ((*testing::make_metric("{type: dominant_joint, prune: 0.99}"))({pred, truth, &c})
                       .at("dominant_joint"),
                   0.0);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::eval

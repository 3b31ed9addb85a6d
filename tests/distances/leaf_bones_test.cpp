// Leaf bones: the paper's zero-length helper against the `extended` construction (ray along the
// parent bone to the surface, bounded by a multiple of the parent's length), its options, and
// what it changes for a distance.

#include <gtest/gtest.h>

#include "framework/core/registry.hpp"
#include "framework/distances/distance.hpp"
#include "framework/distances/leaf_bones.hpp"
#include "framework/geometry/merge_vertices.hpp"
#include "tests/distances/shapes.hpp"
#include "tests/test_util.hpp"

namespace skinlab::distances {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;

LeafBoneOptions parse(const std::string& yaml) {
  return LeafBoneOptions::from(config::Config::parse(yaml, "p.yaml").root()["leaf_bones"]);
}

/// A 1 × 4 × 1 box (y from 0 to 4) with a chain up its axis: root at y = 0.5, a joint at 1.5
/// and the leaf at 2.5. The ray from the leaf along the parent bone (+y) leaves the box at 4.
struct Column {
  geometry::Mesh mesh = testing::MeshBuilder().box({-0.5, 0, -0.5}, {0.5, 4, 0.5}, 3).build();
  geometry::Skeleton skeleton;
  Column() {
    Eigen::MatrixXd joints(3, 3);
    joints << 0, 0.5, 0, 0, 1.5, 0, 0, 2.5, 0;
    skeleton = testing::chain(joints);
  }
};

TEST(LeafBones, ExtendedEndsWhereTheRayLeavesTheMesh) {
  Column c;
  const Eigen::MatrixXd tips = extended_leaf_tips(c.mesh, c.skeleton, 2.0, "column");
  ASSERT_EQ(tips.rows(), 3);
  EXPECT_TRUE(tips.row(0).isApprox(c.skeleton.positions.row(0)));  // joints with children: own
  EXPECT_TRUE(tips.row(1).isApprox(c.skeleton.positions.row(1)));  // position
  EXPECT_NEAR(tips(2, 0), 0, 1e-12);
  EXPECT_NEAR(tips(2, 1), 4.0, 1e-9);  // the top face
  EXPECT_NEAR(tips(2, 2), 0, 1e-12);
}

TEST(LeafBones, ExtendedIsBoundedByTheParentLength) {
  Column c;
  // The parent bone is 1 long; at most 0.75 of it beyond the leaf, short of the top face.
  const Eigen::MatrixXd tips = extended_leaf_tips(c.mesh, c.skeleton, 0.75, "column");
  EXPECT_NEAR(tips(2, 1), 3.25, 1e-12);
}

TEST(LeafBones, LeafOutsideFacingAwayKeepsZeroLength) {
  Column c;
  c.skeleton.positions(2, 1) = 5.0;  // above the box, pointing further up: nothing ahead
  const Eigen::MatrixXd tips = extended_leaf_tips(c.mesh, c.skeleton, 2.0, "column");
  EXPECT_TRUE(tips.row(2).isApprox(c.skeleton.positions.row(2)));
}

TEST(LeafBones, CoincidentParentUsesTheNextAncestorsDirection) {
  Column c;
  c.skeleton.positions.row(1) = c.skeleton.positions.row(2);  // the parent sits on the leaf
  const Eigen::MatrixXd tips = extended_leaf_tips(c.mesh, c.skeleton, 1.0, "column");
  // Direction from the root (y = 0.5) up, bounded by that distance (2): 2.5 + 1.5 to the top.
  EXPECT_NEAR(tips(2, 1), 4.0, 1e-9);
}

/// The column's chain in two closed parts that overlap, as a game head pushed onto a capped body:
/// a body box up to y = 2.6, just above the leaf (2.5), and a head box from y = 2 to 4 around
/// it; a third box from y = 4.5 to 5 above both encloses nothing. Co-located vertices merged,
/// as preprocessing does, so each box is one part.
struct HeadOnBody : Column {
  HeadOnBody() {
    mesh = geometry::merge_vertices(testing::MeshBuilder()
                                        .box({-0.5, 0, -0.5}, {0.5, 2.6, 0.5}, 3)
                                        .box({-0.4, 2, -0.4}, {0.4, 4, 0.4}, 3)
                                        .box({-0.3, 4.5, -0.3}, {0.3, 5, 0.3}, 2)
                                        .build(),
                                    {1e-9})
               .mesh;
  }
};

TEST(LeafBones, EnclosingPartsEndsWhereTheRayLeavesTheLastPartAroundTheLeaf) {
  HeadOnBody c;
  using End = LeafBoneOptions::End;
  // The first surface ahead is the body's cap, 0.1 above the leaf.
  EXPECT_NEAR(extended_leaf_tips(c.mesh, c.skeleton, 3.0, "h", End::kFirstSurface)(2, 1), 2.6,
              1e-9);
  // Both the body (crossed once) and the head (once) enclose the leaf; the head is left last, at
  // its top. The box above, crossed twice, encloses nothing and does not count.
  EXPECT_NEAR(extended_leaf_tips(c.mesh, c.skeleton, 3.0, "h", End::kEnclosingParts)(2, 1), 4.0,
              1e-9);
  // Still bounded by max_length × the parent's length (1).
  EXPECT_NEAR(extended_leaf_tips(c.mesh, c.skeleton, 0.75, "h", End::kEnclosingParts)(2, 1),
              3.25, 1e-12);
  // A leaf below the top box, outside every part: no enclosing part, so the nearest surface.
  c.skeleton.positions(2, 1) = 4.2;
  EXPECT_NEAR(extended_leaf_tips(c.mesh, c.skeleton, 3.0, "h", End::kEnclosingParts)(2, 1), 4.5,
              1e-9);
  // place_leaf_bones reads the option.
  place_leaf_bones(c.mesh, c.skeleton,
                   parse("leaf_bones: {type: extended, max_length: 3, ends_at: enclosing_parts}"),
                   "h");
  EXPECT_NEAR(c.skeleton.leaf_tips(2, 1), 4.5, 1e-9);
}

TEST(LeafBones, SkeletonSegmentsUseTheTipsAndHelperClearsThem) {
  Column c;
  place_leaf_bones(c.mesh, c.skeleton, parse("leaf_bones: extended"), "column");
  const auto bones = c.skeleton.bones();
  ASSERT_EQ(bones.size(), 3u);  // j0->j1, j1->j2, helper at j2
  ASSERT_TRUE(bones[2].helper);
  const Eigen::MatrixXd seg = c.skeleton.bone_segments();
  EXPECT_NEAR(seg(2, 1), 2.5, 1e-12);  // starts at the leaf joint ...
  EXPECT_NEAR(seg(2, 4), 3.5, 1e-9);   // ... ends at the default bound, 1 × the parent's length
  EXPECT_NEAR(seg(1, 4), 2.5, 1e-12);  // other bones unchanged

  // Under the paper's construction the helper is a point at the leaf, the end of the parent bone:
  // a vertex above the leaf is as near to the parent bone as to the helper (the tie); with the
  // extended bone it is nearer to the leaf's own bone.
  const auto euclidean =
      distance_registry().create(config::Config::parse("{type: euclidean}", "d.yaml").root());
  const Eigen::MatrixXd D_extended = euclidean->compute(c.mesh, c.skeleton);
  place_leaf_bones(c.mesh, c.skeleton, parse("leaf_bones: helper"), "column");
  EXPECT_EQ(c.skeleton.leaf_tips.size(), 0);
  const Eigen::MatrixXd D_helper = euclidean->compute(c.mesh, c.skeleton);
  const int top = testing::nearest_vertex(c.mesh, {0, 4, 0});
  EXPECT_DOUBLE_EQ(D_helper(top, 1), D_helper(top, 2));
  EXPECT_LT(D_extended(top, 2), D_extended(top, 1));
}

TEST(LeafBones, ARootWithOneChildGetsAHelperBoneWithRoots) {
  Column c;  // root at y = 0.5 inside the box, its only child above it at 1.5
  using End = LeafBoneOptions::End;
  const Eigen::MatrixXd without = extended_leaf_tips(c.mesh, c.skeleton, 1.0, "column");
  EXPECT_TRUE(without.row(0).isApprox(c.skeleton.positions.row(0)));  // off by default
  // From the root away from its child (-y) to the bottom face, 0.5 below: within 1 × the bone.
  const Eigen::MatrixXd tips =
      extended_leaf_tips(c.mesh, c.skeleton, 1.0, "column", End::kFirstSurface, true);
  EXPECT_NEAR(tips(0, 1), 0.0, 1e-9);
  EXPECT_NEAR(tips(0, 0), 0.0, 1e-12);
  EXPECT_NEAR(tips(2, 1), 3.5, 1e-9);  // the leaf as before
  EXPECT_TRUE(tips.row(1).isApprox(c.skeleton.positions.row(1)));
  // Bounded as a leaf's bone is: 0.25 × the root's bone.
  EXPECT_NEAR(extended_leaf_tips(c.mesh, c.skeleton, 0.25, "column", End::kFirstSurface, true)(0, 1),
              0.25, 1e-12);

  // The skeleton's bones: the root's helper bone first, then RigNet's order.
  EXPECT_FALSE(c.skeleton.has_root_bone());
  place_leaf_bones(c.mesh, c.skeleton, parse("leaf_bones: {type: extended, roots: true}"), "c");
  ASSERT_TRUE(c.skeleton.has_root_bone());
  const auto bones = c.skeleton.bones();
  ASSERT_EQ(bones.size(), 4u);  // root helper, j0->j1, j1->j2, helper at j2
  EXPECT_TRUE(bones[0].helper);
  EXPECT_EQ(bones[0].start, 0);
  EXPECT_EQ(bones[1].end, 1);
  EXPECT_TRUE(bones[3].helper);
  EXPECT_EQ(bones[3].start, 2);
  const Eigen::MatrixXd seg = c.skeleton.bone_segments();
  EXPECT_NEAR(seg(0, 1), 0.5, 1e-12);
  EXPECT_NEAR(seg(0, 4), 0.0, 1e-9);
  // A vertex below the root is nearer to the root's own bone than to its bone to the child.
  const auto euclidean =
      distance_registry().create(config::Config::parse("{type: euclidean}", "d.yaml").root());
  const Eigen::MatrixXd D = euclidean->compute(c.mesh, c.skeleton);
  const int bottom = testing::nearest_vertex(c.mesh, {0, 0, 0});
  EXPECT_LT(D(bottom, 0), D(bottom, 1));
  // A tip within rounding of the root is no bone.
  c.skeleton.leaf_tips.row(0) = c.skeleton.positions.row(0) * (1 + 1e-12);
  EXPECT_FALSE(c.skeleton.has_root_bone());
  EXPECT_EQ(c.skeleton.bones().size(), 3u);
}

TEST(LeafBones, RootsInTheMiddleOrOutsideGetNoHelperBone) {
  using End = LeafBoneOptions::End;
  Column c;
  // A second child of the root (a leg below the hip): the root is inside a chain, not its end.
  c.skeleton.names.push_back("leg");
  c.skeleton.parents.push_back(0);
  c.skeleton.positions.conservativeResize(4, 3);
  c.skeleton.positions.row(3) << 0, 0.2, 0;
  EXPECT_TRUE(extended_leaf_tips(c.mesh, c.skeleton, 1.0, "c", End::kFirstSurface, true)
                  .row(0)
                  .isApprox(c.skeleton.positions.row(0)));
  // A root below the box facing away from it (a ground root under the feet): nothing ahead.
  Column outside;
  outside.skeleton.positions(0, 1) = -0.5;
  place_leaf_bones(outside.mesh, outside.skeleton,
                   parse("leaf_bones: {type: extended, roots: true}"), "c");
  EXPECT_FALSE(outside.skeleton.has_root_bone());
  EXPECT_EQ(outside.skeleton.bones().size(), 3u);
  // A child at the root's position: the direction is the next joint's on the chain.
  Column coincident;
  coincident.skeleton.positions.row(1) = coincident.skeleton.positions.row(0);
  EXPECT_NEAR(extended_leaf_tips(coincident.mesh, coincident.skeleton, 1.0, "c",
                                 End::kFirstSurface, true)(0, 1),
              0.0, 1e-9);
}

TEST(LeafBones, Options) {
  EXPECT_EQ(parse("x: 1").kind, LeafBoneOptions::Kind::kHelper);  // absent: the paper
  EXPECT_EQ(parse("leaf_bones: helper").kind, LeafBoneOptions::Kind::kHelper);
  const auto o = parse("leaf_bones: {type: extended, max_length: 0.5}");
  EXPECT_EQ(o.kind, LeafBoneOptions::Kind::kExtended);
  EXPECT_DOUBLE_EQ(o.max_length, 0.5);
  EXPECT_EQ(o.name(), "extended");
  EXPECT_EQ(o.ends_at, LeafBoneOptions::End::kFirstSurface);  // absent: every earlier dataset
  EXPECT_EQ(parse("leaf_bones: {type: extended, ends_at: enclosing_parts}").ends_at,
            LeafBoneOptions::End::kEnclosingParts);
  EXPECT_FALSE(parse("leaf_bones: {type: extended}").roots);
  EXPECT_TRUE(parse("leaf_bones: {type: extended, roots: true}").roots);
  expect_error<ConfigError>([] { parse("leaf_bones: {type: helper, roots: true}"); },
                            {"roots", "type: extended"});
  expect_error<ConfigError>([] { parse("leaf_bones: {type: extended, ends_at: last}"); },
                            {"ends_at", "'first_surface'", "'enclosing_parts'", "last"});
  expect_error<ConfigError>([] { parse("leaf_bones: longer"); },
                                    {"p.yaml:1", "leaf_bones", "'helper'", "'extended'", "longer"});
  expect_error<ConfigError>([] { parse("leaf_bones: {type: extended, max_length: 0}"); },
                                    {"max_length", "must be positive"});
  expect_error<ConfigError>([] { parse("leaf_bones: {max_length: 2}"); },
                                    {"leaf_bones", "type"});
  expect_error<ConfigError>([] { parse("leaf_bones: {type: extended, max_lenght: 2}"); },
                                    {"max_lenght"});
}

TEST(LeafBones, BadInputIsNamed) {
  Column c;
  expect_error<geometry::GeometryError>(
      [&] { extended_leaf_tips(c.mesh, c.skeleton, -1.0, "column.glb"); },
      {"column.glb", "max_length"});
  c.skeleton.leaf_tips = Eigen::MatrixXd::Zero(2, 3);
  expect_error<geometry::GeometryError>([&] { c.skeleton.validate("rig.txt"); },
                                        {"rig.txt", "leaf tips are 2×3 for 3 joints"});
  c.skeleton.leaf_tips = Eigen::MatrixXd::Zero(3, 3);
  c.skeleton.leaf_tips(1, 0) = std::nan("");
  expect_error<geometry::GeometryError>([&] { c.skeleton.validate("rig.txt"); },
                                        {"rig.txt", "leaf tip of joint 'j1'"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::distances

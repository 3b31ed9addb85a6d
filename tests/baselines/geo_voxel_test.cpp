// Geodesic Voxel Binding (baselines/geo_voxel): the solid voxelisation, the weights on synthetic
// tubes (validity, locality, symmetry, monotonicity, geodesic vs. Euclidean), option errors, and
// the real Minetest player against its artist weights.

#include "baselines/geo_voxel/geo_voxel.hpp"

#include <gtest/gtest.h>

#include <iostream>

#include "tests/baselines/binder_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using baselines::GeoVoxel;
using baselines::GeoVoxelStats;
using baselines::VoxelState;
using testing::Chain;
using testing::expect_error;
using testing::expect_valid_rows;
using testing::make_binder;

int non_zeros(const Eigen::RowVectorXd& row) { return static_cast<int>((row.array() > 0).count()); }

TEST(GeoVoxel, RegisteredWithThePaperDefaults) {
  const auto binder = make_binder("{type: geo_voxel}");
  const auto* g = dynamic_cast<const GeoVoxel*>(binder.get());
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->options().resolution, 128);
  EXPECT_DOUBLE_EQ(g->options().falloff, 0.5);
  EXPECT_EQ(g->options().max_influences, 3);
}

// A closed box is solid: its centre is interior, the cells just outside are exterior, and an
// interior cell exists between every pair of opposite walls.
TEST(GeoVoxel, SolidVoxelsOfAClosedTube) {
  const Chain c = testing::chain();
  const auto surface = geometry::SurfaceVoxels::voxelize(
      c.mesh, geometry::VoxelGrid::fit(c.mesh, c.skeleton, 64, 1));
  const auto state = baselines::solid_voxels(c.mesh, surface);
  const auto& grid = surface.grid();
  EXPECT_EQ(state[grid.cell_of({0, 0.5, 0})], VoxelState::kInterior);
  EXPECT_EQ(state[grid.cell_of({0, 0.2, 0.03})], VoxelState::kInterior);
  EXPECT_EQ(state[grid.cell_of({0.06, 0.5, 0})], VoxelState::kBoundary);
  // Radius 0.06 = 3.8 cells of 1/61 m: two cells beyond the wall is outside.
  EXPECT_EQ(state[grid.cell_of({0.1, 0.5, 0})], VoxelState::kExterior);
  EXPECT_EQ(state[grid.cell_of({0, 0.99, 0})], VoxelState::kExterior);
  // Every cell whose centre is well inside the tube is interior or boundary.
  for (int cell = 0; cell < grid.num_padded(); ++cell) {
    if (!grid.stored(cell)) continue;
    const Eigen::Vector3d p = grid.center(cell);
    const double radial = std::hypot(p.x(), p.z());
    if (radial < 0.045 && p.y() > 0.07 && p.y() < 0.93) {
      EXPECT_NE(state[cell], VoxelState::kExterior) << p.transpose();
    }
    if (radial > 0.08) {
      EXPECT_EQ(state[cell], VoxelState::kExterior) << p.transpose();
    }
  }
}

// An open tube (no caps, a 'game mesh' with two large holes) is still solid inside: along the
// tube's axis the rays escape through the holes, but the two other axes vote inside.
TEST(GeoVoxel, OpenTubeIsStillSolidInside) {
  Chain c = testing::chain();
  const int cap_faces = 2 * Chain::kSides;
  c.mesh.F.conservativeResize(c.mesh.F.rows() - cap_faces, 3);
  const auto surface = geometry::SurfaceVoxels::voxelize(
      c.mesh, geometry::VoxelGrid::fit(c.mesh, c.skeleton, 64, 1));
  const auto state = baselines::solid_voxels(c.mesh, surface);
  EXPECT_EQ(state[surface.grid().cell_of({0, 0.5, 0})], VoxelState::kInterior);
  EXPECT_EQ(state[surface.grid().cell_of({0, 0.07, 0})], VoxelState::kInterior);
  // Above the open end, looking down the tube: only one axis votes, so it stays exterior.
  EXPECT_EQ(state[surface.grid().cell_of({0, 0.99, 0})], VoxelState::kExterior);
  const Eigen::MatrixXd W = GeoVoxel({}).bind(c.mesh, c.skeleton);
  expect_valid_rows(W, c.mesh.num_vertices(), 4);
}

TEST(GeoVoxel, ChainWeightsAreValidLocalAndMonotonic) {
  const Chain c = testing::chain();
  GeoVoxelStats stats;
  const GeoVoxel binder({});
  const Eigen::MatrixXd D = binder.distances(c.mesh, c.skeleton, &stats);
  EXPECT_GT(stats.interior_voxels, 0);
  EXPECT_EQ(stats.snapped_bones, 0);
  EXPECT_EQ(stats.euclidean_vertices, 0);
  EXPECT_TRUE(D.allFinite());
  const Eigen::MatrixXd W = binder.bind(c.mesh, c.skeleton);
  expect_valid_rows(W, c.mesh.num_vertices(), 4);
  for (int v = 0; v < W.rows(); ++v) EXPECT_LE(non_zeros(W.row(v)), 3) << "vertex " << v;

  // Middle of bone 1 (y = 0.5): most of the weight on bone 1.
  for (int j = 0; j < Chain::kSides; ++j) EXPECT_GT(W(Chain::vertex(18, j), 1), 0.6);
  // From j0 (ring 2, y = 0.1) to j3 (ring 34, y = 0.9), bone 0 loses and the last bone with its
  // leaf helper gains weight (2e-3: voxel noise of the offsets). Below j0 bone 0's weight still
  // grows towards its joint, so the end rings are left out.
  for (int i = 2; i < 34; ++i) {
    const int a = Chain::vertex(i, 3), b = Chain::vertex(i + 1, 3);
    EXPECT_LE(W(b, 0), W(a, 0) + 2e-3) << "ring " << i;
    EXPECT_GE(W(b, 2) + W(b, 3), W(a, 2) + W(a, 3) - 2e-3) << "ring " << i;
  }
  EXPECT_GT(W(Chain::vertex(2, 0), 0), 0.8);
  EXPECT_GT(W(Chain::vertex(30, 0), 2) + W(Chain::vertex(30, 0), 3), 0.8);
}

// The tube and its triangulation are symmetric under x → −x (side j ↔ side 8 − j).
TEST(GeoVoxel, MirrorSymmetricInputGivesMirrorSymmetricWeights) {
  const Chain c = testing::chain();
  testing::expect_mirror_symmetric(GeoVoxel({}).bind(c.mesh, c.skeleton));
}

// Wound inwards (as every prepared game character is), the mesh is re-oriented first: same
// weights. Without re-orientation the interior test inverts.
TEST(GeoVoxel, InwardWindingIsReorientedFirst) {
  const Chain c = testing::chain();
  Chain flipped = c;
  flipped.mesh.F.col(1).swap(flipped.mesh.F.col(2));
  GeoVoxelStats stats;
  const Eigen::MatrixXd W = GeoVoxel({}).bind(c.mesh, c.skeleton);
  const Eigen::MatrixXd Wf = GeoVoxel({}).bind(flipped.mesh, flipped.skeleton, &stats);
  EXPECT_EQ(stats.flipped_parts, 1);
  EXPECT_LT((W - Wf).cwiseAbs().maxCoeff(), 1e-12);
  GeoVoxel::Options raw;
  raw.orient_outward = false;
  GeoVoxel(raw).distances(flipped.mesh, flipped.skeleton, &stats);
  EXPECT_EQ(stats.flipped_parts, 0);
  const auto surface = geometry::SurfaceVoxels::voxelize(
      flipped.mesh, geometry::VoxelGrid::fit(flipped.mesh, flipped.skeleton, 64, 1));
  const auto state = baselines::solid_voxels(flipped.mesh, surface);
  EXPECT_EQ(state[surface.grid().cell_of({0, 0.5, 0})], VoxelState::kExterior);
}

// Finger A's inner vertex is 7 cm from B's bone and 8 cm from A's in a straight line, but the
// path through the solid to B's bone runs down A, across the palm and up B.
TEST(GeoVoxel, GeodesicNotEuclidean) {
  const auto f = testing::fingers();
  const int v = f.inner_a();
  const Eigen::Vector3d p = f.mesh.V.row(v).transpose();
  const auto bones = f.skeleton.bones();
  const auto euclid = [&](int b) {
    return geometry::point_segment_distance(p, f.skeleton.positions.row(bones[b].start),
                                            f.skeleton.positions.row(bones[b].end));
  };
  ASSERT_LT(euclid(testing::Fingers::kBoneB), euclid(testing::Fingers::kBoneA));

  const Eigen::MatrixXd D = GeoVoxel({}).distances(f.mesh, f.skeleton);
  EXPECT_NEAR(D(v, testing::Fingers::kBoneA), 0.08, 0.01);
  EXPECT_GT(D(v, testing::Fingers::kBoneB), 0.25);

  const Eigen::MatrixXd W = GeoVoxel({}).bind(f.mesh, f.skeleton);
  expect_valid_rows(W, f.mesh.num_vertices(), 6);
  // A's bone dominates (the rest goes to A's leaf helper and root→a0, geodesically next).
  EXPECT_GT(W(v, testing::Fingers::kBoneA), 0.7);
  EXPECT_EQ(W(v, testing::Fingers::kBoneB), 0.0);
  // With every bone kept, B's bone still gets little.
  GeoVoxel::Options all;
  all.max_influences = 6;
  const Eigen::MatrixXd W6 = GeoVoxel(all).bind(f.mesh, f.skeleton);
  expect_valid_rows(W6, f.mesh.num_vertices(), 6);
  EXPECT_LT(W6(v, testing::Fingers::kBoneB), 0.1 * W6(v, testing::Fingers::kBoneA));
}

// A floating sphere-like tube that no bone reaches through the solid gets Euclidean distances
// instead of no weight.
TEST(GeoVoxel, DisconnectedPartFallsBackToEuclidean) {
  testing::TubeBuilder t;
  t.tube({0, 0.05, 0}, {0, 0.95, 0}, 0.06, Chain::kSides, Chain::kRings);
  const int first = t.num_vertices();
  t.tube({0.3, 0.45, 0}, {0.3, 0.55, 0}, 0.05, 8, 3);
  Chain c = testing::chain();
  c.mesh = t.build();
  GeoVoxelStats stats;
  GeoVoxel({}).distances(c.mesh, c.skeleton, &stats);
  EXPECT_EQ(stats.euclidean_vertices, c.mesh.num_vertices() - first);
  const Eigen::MatrixXd W = GeoVoxel({}).bind(c.mesh, c.skeleton);
  expect_valid_rows(W, c.mesh.num_vertices(), 4);
  // Its nearest bone in a straight line is bone 1 (y 0.37–0.63).
  for (int v = first; v < c.mesh.num_vertices(); ++v) {
    Eigen::Index best;
    W.row(v).maxCoeff(&best);
    EXPECT_EQ(best, 1) << "vertex " << v;
  }
}

// A bone entirely outside the mesh starts at the nearest solid voxel.
TEST(GeoVoxel, OutOfBodyBoneIsSnappedToTheSolid) {
  Chain c = testing::chain();
  c.skeleton.positions(3, 0) = 0.2;  // j3 out to the side: bone 2 leaves the tube, helper j3 out
  GeoVoxelStats stats;
  const Eigen::MatrixXd D = GeoVoxel({}).distances(c.mesh, c.skeleton, &stats);
  EXPECT_EQ(stats.snapped_bones, 1);  // the helper bone at j3; bone 2 still starts inside
  EXPECT_TRUE(D.allFinite());
  expect_valid_rows(GeoVoxel({}).bind(c.mesh, c.skeleton), c.mesh.num_vertices(), 4);
}

TEST(GeoVoxel, BadOptionsNameTheField) {
  expect_error<ConfigError>([] { make_binder("{type: geo_voxel, resolution: 7}"); },
                            {"test.yaml:1", "resolution", "must be at least 8"});
  expect_error<ConfigError>([] { make_binder("{type: geo_voxel, falloff: 1.5}"); },
                            {"falloff", "must be in [0, 1]"});
  expect_error<ConfigError>([] { make_binder("{type: geo_voxel, falloff: -0.1}"); },
                            {"falloff", "must be in [0, 1]"});
  expect_error<ConfigError>([] { make_binder("{type: geo_voxel, max_influences: 0}"); },
                            {"max_influences", "must be at least 1"});
  expect_error<ConfigError>([] { make_binder("{type: geo_voxel, resolutoin: 64}"); },
                            {"resolutoin", "did you mean 'resolution'?"});
}

// The Minetest player (boxes, subdivided to 2702 vertices by the pipeline, 10 bones) against its
// artist weights. Its weights are rigid per box and its leaf joints sit at the limbs' pivots, so
// a limb's artist bone is a helper point at the shoulder or hip: every geometric binder is far
// off. Measured: avg L1 1.405 (uniform weights over the 3 Euclidean-nearest bones: 1.510).
TEST(GeoVoxel, MinetestPlayerBeatsUniformThreeNearest) {
  const auto p = testing::prepared_player();
  GeoVoxelStats stats;
  GeoVoxel({}).distances(p.mesh, p.skeleton, &stats);
  const Eigen::MatrixXd W = GeoVoxel({}).bind(p.mesh, p.skeleton);
  expect_valid_rows(W, p.mesh.num_vertices(), static_cast<int>(p.weights.cols()));
  const double l1 = testing::average_l1(W, p.weights);
  const double uniform =
      testing::average_l1(testing::uniform_three_nearest(p.mesh, p.skeleton), p.weights);
  std::cout << "minetest player: #V=" << p.mesh.num_vertices() << " #B=" << p.weights.cols()
            << " geo_voxel avg L1 " << l1 << ", uniform over 3 nearest " << uniform
            << ", Euclidean-fallback vertices " << stats.euclidean_vertices << ", snapped bones "
            << stats.snapped_bones << "\n";
  EXPECT_LT(l1, uniform);
  EXPECT_LT(l1, 1.45);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

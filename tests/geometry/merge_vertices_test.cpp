#include "framework/geometry/merge_vertices.hpp"

#include <gtest/gtest.h>

#include "framework/geometry/average_vertex_data.hpp"
#include "framework/geometry/gather_vertex_data.hpp"
#include "tests/geometry/test_meshes.hpp"
#include "tests/test_util.hpp"

namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace st = skinlab::testing;
using namespace skinlab::geometry;

TEST(MergeVertices, CubeOfSeparateQuadsMergesToEightConnectedVertices) {
  const Mesh cube = st::cube_as_separate_quads();
  ASSERT_EQ(st::num_components(cube), 6);
  const MergedMesh merged = merge_vertices(cube);
  EXPECT_EQ(merged.mesh.num_vertices(), 8);
  EXPECT_EQ(merged.mesh.num_faces(), 12);
  EXPECT_EQ(merged.kept_faces, Eigen::VectorXi::LinSpaced(12, 0, 11));
  EXPECT_EQ(st::num_components(merged.mesh), 1);
  ASSERT_EQ(merged.old_to_new.size(), 24);
  int next_new = 0;
  for (int v = 0; v < 24; ++v) {
    const int n = merged.old_to_new(v);
    EXPECT_EQ(merged.mesh.V.row(n), cube.V.row(v)) << "vertex " << v;
    // First occurrences are numbered in input order.
    if (n == next_new) ++next_new;
    EXPECT_LT(n, next_new) << "vertex " << v;
  }
  EXPECT_EQ(next_new, 8);
  for (int f = 0; f < 12; ++f) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(merged.mesh.F(f, k), merged.old_to_new(cube.F(f, k)));
  }
  // Closed cube: V − E + F = 2 with E = 3F/2.
  EXPECT_EQ(merged.mesh.num_vertices() - 3 * merged.mesh.num_faces() / 2 +
                merged.mesh.num_faces(),
            2);
}

TEST(MergeVertices, IsDeterministic) {
  const Mesh cube = st::cube_as_separate_quads();
  const MergedMesh a = merge_vertices(cube), b = merge_vertices(cube);
  EXPECT_EQ(a.old_to_new, b.old_to_new);
  EXPECT_EQ(a.mesh.V, b.mesh.V);
  EXPECT_EQ(a.mesh.F, b.mesh.F);
}

TEST(MergeVertices, DenseDataAveragesIntoMergedAndGathersBack) {
  const Mesh cube = st::cube_as_separate_quads();
  const MergedMesh merged = merge_vertices(cube);
  // Per-vertex data: the position plus a per-copy value (side index) that differs between copies.
  Eigen::MatrixXd data(24, 4);
  for (int v = 0; v < 24; ++v) data.row(v) << cube.V.row(v), v / 4;
  const Eigen::MatrixXd on_merged = average_vertex_data(data, merged.old_to_new, 8);
  ASSERT_EQ(on_merged.rows(), 8);
  EXPECT_TRUE(on_merged.leftCols(3).isApprox(merged.mesh.V));
  // Every cube corner is shared by 3 sides; the mean of their side indices.
  Eigen::VectorXd expected_mean = Eigen::VectorXd::Zero(8), count = Eigen::VectorXd::Zero(8);
  for (int v = 0; v < 24; ++v) {
    expected_mean(merged.old_to_new(v)) += v / 4;
    count(merged.old_to_new(v)) += 1;
  }
  EXPECT_EQ(count, Eigen::VectorXd::Constant(8, 3.0));
  EXPECT_TRUE(on_merged.col(3).isApprox(expected_mean.cwiseQuotient(count)));

  const Eigen::MatrixXd back = gather_vertex_data(on_merged, merged.old_to_new);
  ASSERT_EQ(back.rows(), 24);
  for (int v = 0; v < 24; ++v) EXPECT_EQ(back.row(v), on_merged.row(merged.old_to_new(v)));
  EXPECT_TRUE(back.leftCols(3).isApprox(cube.V));
}

TEST(MergeVertices, SparseWeightsAverageKeepsRowSumsAndGathersBack) {
  const Mesh cube = st::cube_as_separate_quads();
  const MergedMesh merged = merge_vertices(cube);
  // Two joints: weight of joint 0 is 1 − z, of joint 1 is z (copies at a corner agree), except
  // one copy of corner 0 whose exporter rounded differently.
  SparseWeights W(24, 2);
  std::vector<Eigen::Triplet<double>> entries;
  for (int v = 0; v < 24; ++v) {
    const double z = cube.V(v, 2);
    if (1 - z > 0) entries.emplace_back(v, 0, 1 - z);
    if (z > 0) entries.emplace_back(v, 1, z);
  }
  W.setFromTriplets(entries.begin(), entries.end());
  W.coeffRef(0, 0) = 0.7;
  W.coeffRef(0, 1) = 0.3;

  const SparseWeights on_merged = average_vertex_data(W, merged.old_to_new, 8);
  ASSERT_EQ(on_merged.rows(), 8);
  ASSERT_EQ(on_merged.cols(), 2);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(on_merged);
  for (int n = 0; n < 8; ++n) EXPECT_NEAR(dense.row(n).sum(), 1.0, 1e-12) << "vertex " << n;
  // Corner 0 (position 0,0,0) has three copies: (1, 0), (1, 0) and (0.7, 0.3).
  EXPECT_NEAR(dense(merged.old_to_new(0), 0), (0.7 + 1 + 1) / 3, 1e-12);
  EXPECT_NEAR(dense(merged.old_to_new(0), 1), 0.3 / 3, 1e-12);

  const SparseWeights back = gather_vertex_data(on_merged, merged.old_to_new);
  ASSERT_EQ(back.rows(), 24);
  const Eigen::MatrixXd back_dense = Eigen::MatrixXd(back), W_dense = Eigen::MatrixXd(W);
  for (int v = 1; v < 24; ++v) {
    if (merged.old_to_new(v) == merged.old_to_new(0)) continue;
    EXPECT_TRUE(back_dense.row(v).isApprox(W_dense.row(v))) << "vertex " << v;
  }
  EXPECT_EQ(back_dense.row(0), dense.row(merged.old_to_new(0)));
}

TEST(MergeVertices, DropsFacesThatBecomeDegenerate) {
  Mesh m;
  m.V.resize(5, 3);
  m.V << 0, 0, 0,  //
      1, 0, 0,     //
      0, 1, 0,     //
      1, 0, 0,     // duplicate of 1
      1, 1, 0;
  m.F.resize(3, 3);
  m.F << 0, 1, 2,  //
      1, 4, 3,     // collapses to (1, 4, 1)
      1, 4, 2;
  const MergedMesh merged = merge_vertices(m);
  EXPECT_EQ(merged.mesh.num_vertices(), 4);
  EXPECT_EQ(merged.old_to_new, (Eigen::VectorXi(5) << 0, 1, 2, 1, 3).finished());
  ASSERT_EQ(merged.mesh.num_faces(), 2);
  EXPECT_EQ(merged.kept_faces, (Eigen::VectorXi(2) << 0, 2).finished());
  EXPECT_EQ(merged.mesh.F.row(1), (Eigen::RowVector3i() << 1, 3, 2).finished());
}

TEST(MergeVertices, ExactByDefaultToleranceOnRequest) {
  Mesh m = st::cube_as_separate_quads();
  // Vertex 5 is the first copy of corner (1, 0, 1); vertex 10 a later copy, slightly off.
  ASSERT_EQ(m.V.row(5), m.V.row(10));
  m.V(10, 0) += 1e-7;
  m.V(0, 0) = -0.0;  // −0 equals +0: corner (0, 0, 0) still merges exactly
  EXPECT_EQ(merge_vertices(m).mesh.num_vertices(), 9);
  EXPECT_EQ(merge_vertices(m, {1e-8}).mesh.num_vertices(), 9);
  const MergedMesh merged = merge_vertices(m, {1e-6});
  EXPECT_EQ(merged.mesh.num_vertices(), 8);
  EXPECT_EQ(merged.old_to_new(10), merged.old_to_new(5));
  // The representative keeps the first occurrence's position, not the off copy's.
  EXPECT_EQ(merged.mesh.V.row(merged.old_to_new(10)), m.V.row(5));
  EXPECT_EQ(st::num_components(merged.mesh), 1);
}

TEST(MergeVertices, ToleranceJoinsTheFirstRepresentativeWithinReach) {
  Mesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0,  //
      0.9, 0, 0,   // beyond 0.5 from vertex 0: a new representative
      0.45, 0, 0,  // within 0.5 of both: joins the first, 0
      0, 1, 0;
  m.F.resize(2, 3);
  m.F << 0, 1, 3,  //
      2, 1, 3;
  const MergedMesh merged = merge_vertices(m, {0.5});
  EXPECT_EQ(merged.old_to_new, (Eigen::VectorXi(4) << 0, 1, 0, 2).finished());
  EXPECT_EQ(merged.mesh.num_faces(), 2);
}

TEST(MergeVertices, RejectsBadInput) {
  st::expect_error<GeometryError>([] { merge_vertices(Mesh{}); },
                                       {"merge_vertices", "no vertices"});
  st::expect_error<GeometryError>(
      [] { merge_vertices(st::tetrahedron(), {-1.0}); }, {"merge_vertices", "tolerance"});
  st::expect_error<GeometryError>(
      [] { merge_vertices(st::tetrahedron(), {10.0}); },
      {"merge_vertices", "every one of the 4 faces became degenerate"});
  const Eigen::VectorXi bad_map = (Eigen::VectorXi(2) << 0, 3).finished();
  st::expect_error<GeometryError>(
      [&] { gather_vertex_data(Eigen::MatrixXd::Zero(2, 1), bad_map); },
      {"gather_vertex_data", "original vertex 1 maps to 3"});
  st::expect_error<GeometryError>(
      [&] { average_vertex_data(Eigen::MatrixXd::Zero(2, 1), bad_map, 4); },
      {"average_vertex_data", "new vertex 1 has no original vertex"});
  st::expect_error<GeometryError>(
      [&] { average_vertex_data(Eigen::MatrixXd::Zero(3, 1), bad_map, 4); },
      {"average_vertex_data", "3 rows", "2 original vertices"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace

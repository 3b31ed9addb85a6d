#include "framework/geometry/subdivide.hpp"

#include <gtest/gtest.h>

#include <map>
#include <utility>

#include "tests/geometry/test_meshes.hpp"
#include "tests/test_util.hpp"

namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace st = skinlab::testing;
using namespace skinlab::geometry;

// Undirected edges (min, max) and how many faces use each.
std::map<std::pair<int, int>, int> edge_use(const Mesh& m) {
  std::map<std::pair<int, int>, int> use;
  for (int f = 0; f < m.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = m.F(f, k), b = m.F(f, (k + 1) % 3);
      ++use[{std::min(a, b), std::max(a, b)}];
    }
  }
  return use;
}

// Checks S: first #V_old rows are the identity, every row sums to 1, V_new = S · V_old.
void expect_interpolation(const SubdividedMesh& s, const Mesh& original) {
  const int n_old = original.num_vertices();
  ASSERT_EQ(s.S.rows(), s.mesh.num_vertices());
  ASSERT_EQ(s.S.cols(), n_old);
  const Eigen::MatrixXd S = Eigen::MatrixXd(s.S);
  EXPECT_EQ(S.topRows(n_old), Eigen::MatrixXd::Identity(n_old, n_old));
  EXPECT_TRUE(S.rowwise().sum().isApprox(Eigen::VectorXd::Ones(S.rows())));
  EXPECT_GE(S.minCoeff(), 0.0);
  EXPECT_TRUE((s.S * original.V).isApprox(s.mesh.V, 1e-14));
}

TEST(Subdivide, OneStepAddsOneVertexPerEdgeAndQuadruplesFaces) {
  for (const Mesh& m : {st::tetrahedron(), st::grid(2, 2), st::grid(3, 1, 0.1)}) {
    const int edges = static_cast<int>(edge_use(m).size());
    const SubdividedMesh s = subdivide(m, {m.num_vertices() + 1, 100000});
    EXPECT_EQ(s.levels, 1);
    EXPECT_EQ(s.mesh.num_vertices(), m.num_vertices() + edges);
    EXPECT_EQ(s.mesh.num_faces(), 4 * m.num_faces());
    EXPECT_EQ(s.mesh.V.topRows(m.num_vertices()), m.V);
    expect_interpolation(s, m);
    EXPECT_EQ(st::num_components(s.mesh), 1);
  }
}

TEST(Subdivide, NewVerticesAreEdgeMidpointsOfTheirTwoParents) {
  const Mesh m = st::tetrahedron();
  const SubdividedMesh s = subdivide(m, {5, 100});
  const auto edges = edge_use(m);
  std::map<std::pair<int, int>, int> seen;
  for (int v = m.num_vertices(); v < s.mesh.num_vertices(); ++v) {
    std::vector<std::pair<int, double>> parents;
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(s.S, v); it; ++it) {
      parents.emplace_back(static_cast<int>(it.col()), it.value());
    }
    ASSERT_EQ(parents.size(), 2u) << "vertex " << v;
    EXPECT_EQ(parents[0].second, 0.5);
    EXPECT_EQ(parents[1].second, 0.5);
    const int a = parents[0].first, b = parents[1].first;
    EXPECT_TRUE(edges.count({a, b})) << a << "-" << b << " is not an edge";
    EXPECT_EQ((++seen[{a, b}]), 1) << "edge " << a << "-" << b << " got two midpoints";
    EXPECT_EQ(s.mesh.V.row(v), 0.5 * (m.V.row(a) + m.V.row(b)));
  }
  EXPECT_EQ(seen.size(), edges.size());
  // Face (a, b, c) → corner triangles keep the orientation: (a, m_ab, m_ca) first.
  EXPECT_EQ(s.mesh.F(0, 0), m.F(0, 0));
  EXPECT_EQ(s.mesh.F(5, 1), m.F(1, 1));
}

TEST(Subdivide, TetrahedronReachesTheRangeClosedAndConnected) {
  const Mesh m = st::tetrahedron();
  const SubdividedMesh s = subdivide(m);  // 4 → 10 → 34 → 130 → 514 → 2050
  EXPECT_EQ(s.levels, 5);
  EXPECT_EQ(s.mesh.num_vertices(), 2050);
  EXPECT_GE(s.mesh.num_vertices(), 1000);
  EXPECT_LE(s.mesh.num_vertices(), 5000);
  EXPECT_EQ(s.mesh.num_faces(), 4 * 1024);
  EXPECT_EQ(st::num_components(s.mesh), 1);
  // Still a closed 2-manifold: every edge in exactly two faces, Euler characteristic 2.
  const auto use = edge_use(s.mesh);
  for (const auto& [edge, count] : use) {
    ASSERT_EQ(count, 2) << "edge " << edge.first << "-" << edge.second;
  }
  EXPECT_EQ(s.mesh.num_vertices() - static_cast<int>(use.size()) + s.mesh.num_faces(), 2);
  expect_interpolation(s, m);
  s.mesh.validate("subdivided tetrahedron");
}

TEST(Subdivide, StopsBeforeExceedingMaxAndLeavesLargeMeshesAlone) {
  const Mesh m = st::tetrahedron();
  const SubdividedMesh capped = subdivide(m, {1000, 1000});  // 2050 would exceed 1000
  EXPECT_EQ(capped.levels, 4);
  EXPECT_EQ(capped.mesh.num_vertices(), 514);
  expect_interpolation(capped, m);

  const SubdividedMesh same = subdivide(m, {4, 5000});
  EXPECT_EQ(same.levels, 0);
  EXPECT_EQ(same.mesh.V, m.V);
  EXPECT_EQ(same.mesh.F, m.F);
  expect_interpolation(same, m);
}

TEST(Subdivide, InterpolatesPerVertexDataAndIsDeterministic) {
  const Mesh m = st::grid(4, 3, 0.05);
  const SubdividedMesh a = subdivide(m, {200, 5000}), b = subdivide(m, {200, 5000});
  EXPECT_EQ(a.mesh.F, b.mesh.F);
  EXPECT_EQ(a.mesh.V, b.mesh.V);
  // A linear function of position is reproduced exactly by midpoint interpolation.
  const Eigen::VectorXd f_old = m.V * Eigen::Vector3d(2.0, -1.0, 0.5);
  const Eigen::VectorXd f_new = a.S * f_old;
  EXPECT_TRUE(f_new.isApprox(a.mesh.V * Eigen::Vector3d(2.0, -1.0, 0.5), 1e-12));
  EXPECT_EQ(f_new.head(m.num_vertices()), f_old);
}

TEST(Subdivide, DegenerateEdgesGetNoMidpoint) {
  Mesh m = st::grid(1, 1);
  m.F.conservativeResize(3, 3);
  m.F.row(2) << 0, 0, 1;  // index-degenerate face: only the edge 0-1 is real
  const SubdividedMesh s = subdivide(m, {5, 100});
  EXPECT_EQ(s.mesh.num_vertices(), 4 + 5);
  EXPECT_EQ(s.mesh.num_faces(), 12);
  expect_interpolation(s, m);
}

TEST(Subdivide, RejectsBadInput) {
  st::expect_error<GeometryError>([] { subdivide(Mesh{}); }, {"subdivide", "no vertices"});
  st::expect_error<GeometryError>([] { subdivide(st::tetrahedron(), {6000, 5000}); },
                                       {"subdivide", "min_vertices (6000)", "max_vertices (5000)"});
  Mesh bad = st::tetrahedron();
  bad.F(2, 1) = 7;
  st::expect_error<GeometryError>([&] { subdivide(bad); },
                                       {"subdivide", "face 2 refers to vertex 7"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace

#include "framework/geometry/laplacian.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "framework/geometry/one_ring.hpp"
#include "framework/geometry/subdivide.hpp"
#include "tests/geometry/test_meshes.hpp"
#include "tests/test_util.hpp"

namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace st = skinlab::testing;
using namespace skinlab::geometry;

const LaplacianOptions kUniform{LaplacianKind::kUniform};
const LaplacianOptions kCotangent{LaplacianKind::kCotangent};

// Symmetric, zero row sums, finite, PSD (smallest eigenvalue ≥ −1e-9 relative to the largest).
void expect_laplacian_properties(const Eigen::SparseMatrix<double>& L, const char* what) {
  SCOPED_TRACE(what);
  const Eigen::MatrixXd D = Eigen::MatrixXd(L);
  ASSERT_TRUE(D.allFinite());
  EXPECT_EQ(D, D.transpose());
  const double scale = std::max(1.0, D.cwiseAbs().maxCoeff());
  EXPECT_LE(D.rowwise().sum().cwiseAbs().maxCoeff(), 1e-12 * scale);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(D, Eigen::EigenvaluesOnly);
  EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-9 * scale);
}

// A small closed mesh with obtuse triangles: a tetrahedron subdivided once, then squashed.
Mesh squashed_sphere() {
  Mesh m = subdivide(st::tetrahedron(), {5, 100}).mesh;
  m.V.col(2) *= 0.2;
  return m;
}

TEST(Laplacian, UniformByHand) {
  Mesh tri;
  tri.V.resize(3, 3);
  tri.V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  tri.F.resize(1, 3);
  tri.F << 0, 1, 2;
  Eigen::Matrix3d expected;
  expected << 2, -1, -1, -1, 2, -1, -1, -1, 2;
  EXPECT_EQ(Eigen::MatrixXd(laplacian(tri)), expected);

  // Two triangles sharing edge 1–2 (a path 0 – {1, 2} – 3): vertices 0 and 3 are not adjacent,
  // and the shared edge still weighs 1.
  Mesh strip;
  strip.V.resize(4, 3);
  strip.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0;
  strip.F.resize(2, 3);
  strip.F << 0, 1, 2, 1, 3, 2;
  Eigen::Matrix4d expected4;
  expected4 << 2, -1, -1, 0,  //
      -1, 3, -1, -1,          //
      -1, -1, 3, -1,          //
      0, -1, -1, 2;
  EXPECT_EQ(Eigen::MatrixXd(laplacian(strip, kUniform)), expected4);
}

TEST(Laplacian, UniformQuadraticFormSumsSquaredEdgeDifferences) {
  const Mesh m = st::grid(3, 2);
  const Eigen::SparseMatrix<double> L = laplacian(m);
  Eigen::VectorXd w(m.num_vertices());
  for (int i = 0; i < w.size(); ++i) w(i) = std::sin(1.3 * i);
  const auto ring = one_ring(m);
  double expected = 0;
  for (Eigen::Index e = 0; e < ring.edges.cols(); ++e) {
    expected += 0.5 * std::pow(w(ring.edges(0, e)) - w(ring.edges(1, e)), 2);
  }
  EXPECT_NEAR(w.dot(L * w), expected, 1e-12);
}

TEST(Laplacian, CotangentOfAnEquilateralTriangle) {
  Mesh tri;
  tri.V.resize(3, 3);
  tri.V << 0, 0, 0, 1, 0, 0, 0.5, std::sqrt(3.0) / 2, 0;
  tri.F.resize(1, 3);
  tri.F << 0, 1, 2;
  Eigen::Matrix3d expected;
  expected << 2, -1, -1, -1, 2, -1, -1, -1, 2;
  expected *= 0.5 / std::sqrt(3.0);  // ½ cot 60° per edge
  EXPECT_TRUE(Eigen::MatrixXd(laplacian(tri, kCotangent)).isApprox(expected, 1e-12));
}

TEST(Laplacian, CotangentOfAFlatRegularGridIsTheFivePointStencil) {
  const Mesh m = st::grid(4, 4, 0.37);  // scale-invariant: any spacing gives the same
  const Eigen::MatrixXd L = Eigen::MatrixXd(laplacian(m, kCotangent));
  for (int j = 1; j < 4; ++j) {
    for (int i = 1; i < 4; ++i) {
      const int v = j * 5 + i;
      EXPECT_NEAR(L(v, v), 4, 1e-12) << "vertex " << v;
      for (int u : {v - 1, v + 1, v - 5, v + 5}) EXPECT_NEAR(L(v, u), -1, 1e-12);
      // Diagonal edges lie opposite two right angles: cot 90° = 0.
      EXPECT_NEAR(L(v, v + 6), 0, 1e-12);
      EXPECT_NEAR(L(v, v - 6), 0, 1e-12);
      EXPECT_NEAR(L.row(v).cwiseAbs().sum(), 8, 1e-12);
    }
  }
}

TEST(Laplacian, BothKindsAreSymmetricZeroRowSumAndPositiveSemiDefinite) {
  for (const Mesh& m : {st::tetrahedron(), squashed_sphere(), st::grid(5, 4, 0.1, 0.3)}) {
    expect_laplacian_properties(laplacian(m, kUniform), "uniform");
    expect_laplacian_properties(laplacian(m, kCotangent), "cotangent");
    expect_laplacian_properties(laplacian(m, {LaplacianKind::kCotangent, true}), "clamped");
  }
}

TEST(Laplacian, ClampingRemovesNegativeCotangentWeights) {
  // One very obtuse triangle: the edge opposite the 150°-ish angle gets a negative weight.
  Mesh m;
  m.V.resize(3, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0.5, 0.1, 0;
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  const Eigen::MatrixXd raw = Eigen::MatrixXd(laplacian(m, kCotangent));
  EXPECT_GT(raw(0, 1), 0);  // off-diagonal > 0 means edge weight < 0
  expect_laplacian_properties(laplacian(m, kCotangent), "raw obtuse");
  const Eigen::MatrixXd clamped =
      Eigen::MatrixXd(laplacian(m, {LaplacianKind::kCotangent, true}));
  EXPECT_EQ(clamped(0, 1), 0);
  EXPECT_NEAR(clamped(0, 2), raw(0, 2), 1e-15);
  expect_laplacian_properties(laplacian(m, {LaplacianKind::kCotangent, true}), "clamped obtuse");
}

TEST(Laplacian, DegenerateAndNonManifoldTrianglesGiveNoNaN) {
  Mesh m = st::grid(2, 2, 0.1);
  const int n = m.num_vertices();
  m.V.conservativeResize(n + 3, 3);
  m.V.row(n) << 0.05, 0, 0;          // collinear with vertices 0 and 1: zero area
  m.V.row(n + 1) << 0.1, 0, 1e-14;   // needle on top of vertex 1
  m.V.row(n + 2) << 0.05, 0.05, 0.2;  // a fin on the diagonal edge 0–4: non-manifold
  const int f = m.num_faces();
  m.F.conservativeResize(f + 4, 3);
  m.F.row(f) << 0, n, 1;
  m.F.row(f + 1) << 1, n + 1, 2;
  m.F.row(f + 2) << 0, 4, n + 2;
  m.F.row(f + 3) << 3, 3, 4;  // repeated index
  for (const LaplacianOptions& options : {kUniform, kCotangent}) {
    const Eigen::SparseMatrix<double> L = laplacian(m, options);
    expect_laplacian_properties(L, options.kind == LaplacianKind::kUniform ? "uniform" : "cot");
  }
  // Without the degenerate-triangle rule the zero-area face would divide by zero.
  const Eigen::MatrixXd cot = Eigen::MatrixXd(laplacian(m, kCotangent));
  EXPECT_EQ(cot(n, n), 0);  // only in the zero-area face: no weight at all
}

TEST(Laplacian, RejectsBadInput) {
  st::expect_error<GeometryError>([] { laplacian(Mesh{}); }, {"laplacian", "no vertices"});
  st::expect_error<GeometryError>(
      [] { laplacian(st::tetrahedron(), {LaplacianKind::kCotangent, false, -1.0}); },
      {"laplacian", "degenerate_ratio"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace

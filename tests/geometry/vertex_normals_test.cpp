// vertex_normals: area weighting, the winding's sign, and zero for a vertex on no face.

#include "framework/geometry/vertex_normals.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/geometry/test_meshes.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

TEST(VertexNormals, FlatGridPointsAlongPlusZ) {
  const Mesh m = testing::grid(3, 2, 0.5, 0.1);  // counter-clockwise seen from +z
  const Eigen::MatrixXd n = vertex_normals(m);
  ASSERT_EQ(n.rows(), m.V.rows());
  for (Eigen::Index v = 0; v < n.rows(); ++v) {
    EXPECT_NEAR(n(v, 2), 1.0, 1e-12) << "vertex " << v;
  }
}

TEST(VertexNormals, TetrahedronCornerIsTheAreaWeightedMeanOfItsFaces) {
  const Mesh m = testing::tetrahedron();  // wound outwards
  const Eigen::MatrixXd n = vertex_normals(m);
  // Vertex 0 (the origin) touches the three axis-aligned faces of area 1/2 with normals −x, −y,
  // −z: equal weights, so the normal is −(1, 1, 1)/√3.
  const double s = 1.0 / std::sqrt(3.0);
  EXPECT_TRUE(n.row(0).isApprox(Eigen::RowVector3d(-s, -s, -s), 1e-12)) << n.row(0);
  // Vertex 1 = (1, 0, 0): faces −z and −y (area 1/2) and the slanted face (area √3/2, normal
  // (1, 1, 1)/√3): sum = (0, −1/2, −1/2) + (1/2, 1/2, 1/2) = (1/2, 0, 0) → +x.
  EXPECT_TRUE(n.row(1).isApprox(Eigen::RowVector3d(1, 0, 0), 1e-12)) << n.row(1);
  // Flipping every face flips every normal.
  Mesh flipped = m;
  flipped.F.col(1).swap(flipped.F.col(2));
  EXPECT_TRUE(vertex_normals(flipped).isApprox(-n, 1e-12));
}

TEST(VertexNormals, VertexOnNoFaceIsZero) {
  Mesh m = testing::tetrahedron();
  m.V.conservativeResize(5, 3);
  m.V.row(4) << 3, 3, 3;
  const Eigen::MatrixXd n = vertex_normals(m);
  EXPECT_EQ(n.row(4).norm(), 0.0);
  for (int v = 0; v < 4; ++v) EXPECT_NEAR(n.row(v).norm(), 1.0, 1e-12);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

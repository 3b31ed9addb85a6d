// mesh_parts: vertices joined by shared faces, with every face or with a chosen list of faces.

#include "framework/geometry/mesh_parts.hpp"

#include <gtest/gtest.h>

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

/// Two triangles sharing vertex 2 (vertices 0-4), a separate triangle (5-7) and a vertex in no
/// face (8).
Mesh three_parts() {
  Mesh m;
  m.V = Eigen::MatrixXd::Random(9, 3);
  m.F.resize(3, 3);
  m.F << 0, 1, 2, 2, 3, 4, 5, 6, 7;
  return m;
}

TEST(MeshParts, SharedVerticesJoinAndEachPartHasOneRepresentative) {
  const Mesh m = three_parts();
  const std::vector<int> part = vertex_parts(m);
  ASSERT_EQ(part.size(), 9u);
  for (int v : {1, 2, 3, 4}) EXPECT_EQ(part[v], part[0]);
  for (int v : {6, 7}) EXPECT_EQ(part[v], part[5]);
  EXPECT_NE(part[0], part[5]);
  EXPECT_EQ(part[8], 8);
  int representatives = 0;
  for (int v = 0; v < 9; ++v) {
    EXPECT_EQ(part[part[v]], part[v]);
    representatives += part[v] == v;
  }
  EXPECT_EQ(representatives, 3);
}

TEST(MeshParts, OnlyTheListedFacesJoin) {
  const Mesh m = three_parts();
  const std::vector<int> part = vertex_parts(m, {0, 2});  // the second triangle left out
  EXPECT_EQ(part[1], part[0]);
  EXPECT_EQ(part[2], part[0]);
  EXPECT_NE(part[3], part[0]);
  EXPECT_EQ(part[3], 3);
  EXPECT_EQ(part[4], 4);
  EXPECT_EQ(part[7], part[5]);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

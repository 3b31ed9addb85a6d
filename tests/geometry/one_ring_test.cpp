#include "framework/geometry/one_ring.hpp"

#include <gtest/gtest.h>

#include <set>
#include <utility>

#include "tests/geometry/test_meshes.hpp"
#include "tests/test_util.hpp"

namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace st = skinlab::testing;
using namespace skinlab::geometry;
using List = std::vector<int>;

TEST(OneRing, TetrahedronIsTheCompleteGraph) {
  const OneRing ring = one_ring(st::tetrahedron());
  ASSERT_EQ(ring.neighbours.size(), 4u);
  EXPECT_EQ(ring.neighbours[0], (List{1, 2, 3}));
  EXPECT_EQ(ring.neighbours[1], (List{0, 2, 3}));
  EXPECT_EQ(ring.neighbours[2], (List{0, 1, 3}));
  EXPECT_EQ(ring.neighbours[3], (List{0, 1, 2}));
  ASSERT_EQ(ring.edges.cols(), 12);
  EXPECT_EQ(ring.edges.col(0), Eigen::Vector2i(0, 1));
  EXPECT_EQ(ring.edges.col(3), Eigen::Vector2i(1, 0));
  EXPECT_EQ(ring.edges.col(11), Eigen::Vector2i(3, 2));
}

TEST(OneRing, GridByHand) {
  // 3×3 vertices:  6 7 8
  //                3 4 5     cells split along (i, j)–(i+1, j+1)
  //                0 1 2
  const OneRing ring = one_ring(st::grid(2, 2));
  EXPECT_EQ(ring.neighbours[4], (List{0, 1, 3, 5, 7, 8}));
  EXPECT_EQ(ring.neighbours[0], (List{1, 3, 4}));
  EXPECT_EQ(ring.neighbours[2], (List{1, 5}));
  EXPECT_EQ(ring.neighbours[6], (List{3, 7}));
  EXPECT_EQ(ring.neighbours[8], (List{4, 5, 7}));
  EXPECT_EQ(ring.neighbours[1], (List{0, 2, 4, 5}));
}

TEST(OneRing, EdgesAreBothDirectionsOfEveryNeighbourSorted) {
  const Mesh m = st::grid(5, 4, 0.1);
  const OneRing ring = one_ring(m);
  std::set<std::pair<int, int>> directed;
  for (Eigen::Index e = 0; e < ring.edges.cols(); ++e) {
    directed.insert({ring.edges(0, e), ring.edges(1, e)});
    if (e > 0) {
      EXPECT_LT(std::make_pair(ring.edges(0, e - 1), ring.edges(1, e - 1)),
                std::make_pair(ring.edges(0, e), ring.edges(1, e)));
    }
  }
  EXPECT_EQ(directed.size(), static_cast<size_t>(ring.edges.cols()));
  for (const auto& [i, j] : directed) {
    EXPECT_TRUE(directed.count({j, i})) << i << "->" << j;
    EXPECT_NE(i, j);
  }
  // Undirected edges: nx·(ny+1) horizontal + (nx+1)·ny vertical + nx·ny diagonal.
  EXPECT_EQ(ring.edges.cols(), 2 * (5 * 5 + 6 * 4 + 5 * 4));
  size_t from_lists = 0;
  for (const auto& list : ring.neighbours) from_lists += list.size();
  EXPECT_EQ(from_lists, static_cast<size_t>(ring.edges.cols()));
}

TEST(OneRing, NoSelfLoopsFromDegenerateFacesAndEmptyListsForIsolatedVertices) {
  Mesh m = st::grid(1, 1);
  m.V.conservativeResize(5, 3);
  m.V.row(4) << 7, 7, 7;  // referenced by no face
  m.F.conservativeResize(3, 3);
  m.F.row(2) << 1, 1, 2;
  const OneRing ring = one_ring(m);
  EXPECT_EQ(ring.neighbours[1], (List{0, 2, 3}));
  EXPECT_TRUE(ring.neighbours[4].empty());
}

TEST(OneRing, NonManifoldEdgeCollectsAllFaces) {
  Mesh m;
  m.V.resize(5, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1;
  m.F.resize(3, 3);
  m.F << 0, 1, 2, 1, 0, 3, 0, 1, 4;  // edge 0-1 in three faces
  const OneRing ring = one_ring(m);
  EXPECT_EQ(ring.neighbours[0], (List{1, 2, 3, 4}));
  EXPECT_EQ(ring.neighbours[1], (List{0, 2, 3, 4}));
}

TEST(OneRing, RejectsBadInput) {
  st::expect_error<GeometryError>([] { one_ring(Mesh{}); }, {"one_ring", "no vertices"});
  Mesh m = st::tetrahedron();
  m.V(1, 2) = std::nan("");
  st::expect_error<GeometryError>([&] { one_ring(m); }, {"one_ring", "vertex 1", "non-finite"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace

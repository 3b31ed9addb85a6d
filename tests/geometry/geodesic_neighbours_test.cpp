#include "framework/geometry/geodesic_neighbours.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

#include "tests/geometry/test_meshes.hpp"
#include "tests/test_util.hpp"

namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace st = skinlab::testing;
using namespace skinlab::geometry;

// Naive reference: all-pairs shortest paths over the face edges (Floyd–Warshall).
Eigen::MatrixXd floyd_warshall(const Mesh& m) {
  const int n = m.num_vertices();
  Eigen::MatrixXd D = Eigen::MatrixXd::Constant(n, n, std::numeric_limits<double>::infinity());
  for (int i = 0; i < n; ++i) D(i, i) = 0;
  for (int f = 0; f < m.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = m.F(f, k), b = m.F(f, (k + 1) % 3);
      const double len = (m.V.row(a) - m.V.row(b)).norm();
      D(a, b) = D(b, a) = std::min(D(a, b), len);
    }
  }
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) D(i, j) = std::min(D(i, j), D(i, k) + D(k, j));
  return D;
}

// Reference ball of i: (distance, index) of all j ≠ i within the radius, sorted.
std::vector<std::pair<double, int>> reference_ball(const Eigen::MatrixXd& D, int i, double r) {
  std::vector<std::pair<double, int>> ball;
  for (int j = 0; j < D.cols(); ++j) {
    if (j != i && D(i, j) <= r) ball.emplace_back(D(i, j), j);
  }
  std::sort(ball.begin(), ball.end());
  return ball;
}

// Jittered 8×8-vertex grid, 1 cm spacing: distance ties and radius-boundary cases are unlikely.
const Mesh& test_grid() {
  static const Mesh m = st::grid(7, 7, 0.01, 0.2);
  return m;
}

constexpr double kRadius = 0.025;

TEST(GeodesicNeighbours, UncappedBallsMatchFloydWarshall) {
  const Mesh& m = test_grid();
  const Eigen::MatrixXd D = floyd_warshall(m);
  const GeodesicNeighbours g = geodesic_neighbours(m, {kRadius, 0});
  size_t total = 0;
  for (int i = 0; i < m.num_vertices(); ++i) {
    const auto ball = reference_ball(D, i, kRadius);
    // No reference distance sits on the boundary, so rounding cannot flip membership.
    for (int j = 0; j < m.num_vertices(); ++j) ASSERT_GT(std::abs(D(i, j) - kRadius), 1e-9);
    ASSERT_EQ(g.neighbours[i].size(), ball.size()) << "vertex " << i;
    EXPECT_EQ(g.ball_size(i), static_cast<int>(ball.size()));
    for (size_t k = 0; k < ball.size(); ++k) {
      EXPECT_EQ(g.neighbours[i][k], ball[k].second) << "vertex " << i << " rank " << k;
      EXPECT_NEAR(g.distances[i][k], ball[k].first, 1e-12);
    }
    total += ball.size();
  }
  EXPECT_GT(total, 10u * m.num_vertices());  // the radius is large enough to need the cap
  ASSERT_EQ(g.edges.cols(), static_cast<Eigen::Index>(total));
}

TEST(GeodesicNeighbours, NearestCapKeepsTheClosest) {
  const Mesh& m = test_grid();
  const Eigen::MatrixXd D = floyd_warshall(m);
  const GeodesicNeighbours g = geodesic_neighbours(m, {kRadius, 10, NeighbourCap::kNearest});
  for (int i = 0; i < m.num_vertices(); ++i) {
    auto ball = reference_ball(D, i, kRadius);
    if (ball.size() > 10) ball.resize(10);
    ASSERT_EQ(g.neighbours[i].size(), ball.size());
    for (size_t k = 0; k < ball.size(); ++k) EXPECT_EQ(g.neighbours[i][k], ball[k].second);
  }
}

TEST(GeodesicNeighbours, StratifiedCapSpreadsOverTheWholeBall) {
  const Mesh& m = test_grid();
  const Eigen::MatrixXd D = floyd_warshall(m);
  const GeodesicNeighbours g = geodesic_neighbours(m);  // defaults: stratified, 10
  const GeodesicNeighbours wide = geodesic_neighbours(m, {kRadius, 10});
  for (int i = 0; i < m.num_vertices(); ++i) {
    const auto ball = reference_ball(D, i, kRadius);
    const size_t n = ball.size();
    ASSERT_EQ(wide.neighbours[i].size(), std::min<size_t>(n, 10));
    EXPECT_EQ(wide.ball_size(i), static_cast<int>(n));
    for (size_t k = 0; k < wide.neighbours[i].size(); ++k) {
      const size_t rank = n > 10 ? (2 * k + 1) * n / 20 : k;
      EXPECT_EQ(wide.neighbours[i][k], ball[rank].second) << "vertex " << i << " pick " << k;
    }
    if (n > 10) {  // reaches beyond the 10 nearest, i.e. towards the rim of the ball
      EXPECT_GT(wide.distances[i].back(), ball[9].first);
    }
    // At the default 6 cm radius the 1 cm grid is covered far beyond the cap.
    EXPECT_EQ(g.neighbours[i].size(), 10u);
  }
}

TEST(GeodesicNeighbours, RandomCapIsASeededSubsetOfTheBall) {
  const Mesh& m = test_grid();
  const Eigen::MatrixXd D = floyd_warshall(m);
  GeodesicOptions options{kRadius, 10, NeighbourCap::kRandom, 7};
  const GeodesicNeighbours a = geodesic_neighbours(m, options);
  const GeodesicNeighbours b = geodesic_neighbours(m, options);
  options.seed = 8;
  const GeodesicNeighbours c = geodesic_neighbours(m, options);
  bool seeds_differ = false;
  for (int i = 0; i < m.num_vertices(); ++i) {
    const auto ball = reference_ball(D, i, kRadius);
    std::set<int> members;
    for (const auto& [d, j] : ball) members.insert(j);
    ASSERT_EQ(a.neighbours[i].size(), std::min<size_t>(ball.size(), 10));
    EXPECT_EQ(std::set<int>(a.neighbours[i].begin(), a.neighbours[i].end()).size(),
              a.neighbours[i].size());
    for (int j : a.neighbours[i]) EXPECT_TRUE(members.count(j)) << i << "->" << j;
    EXPECT_TRUE(std::is_sorted(a.distances[i].begin(), a.distances[i].end()));
    EXPECT_EQ(a.neighbours[i], b.neighbours[i]);
    seeds_differ = seeds_differ || a.neighbours[i] != c.neighbours[i];
  }
  EXPECT_TRUE(seeds_differ);
}

TEST(GeodesicNeighbours, IndependentOfTheThreadCount) {
  const Mesh m = st::grid(20, 20, 0.01, 0.2);
  for (const NeighbourCap cap :
       {NeighbourCap::kStratified, NeighbourCap::kNearest, NeighbourCap::kRandom}) {
    GeodesicNeighbours one, two;
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
      one = geodesic_neighbours(m, {0.06, 10, cap, 3});
    }
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
      two = geodesic_neighbours(m, {0.06, 10, cap, 3});
    }
    EXPECT_EQ(one.neighbours, two.neighbours);
    EXPECT_EQ(one.distances, two.distances);
    EXPECT_EQ(one.edges, two.edges);
  }
}

TEST(GeodesicNeighbours, EdgesFollowTheListsAndDisjointPartsAreNotNeighbours) {
  // Two triangles 1 mm apart in space but not connected.
  Mesh m;
  m.V.resize(6, 3);
  m.V << 0, 0, 0, 0.01, 0, 0, 0, 0.01, 0,  //
      0, 0, 0.001, 0.01, 0, 0.001, 0, 0.01, 0.001;
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 3, 4, 5;
  const GeodesicNeighbours g = geodesic_neighbours(m);
  EXPECT_EQ(g.neighbours[0], (std::vector<int>{1, 2}));
  EXPECT_EQ(g.neighbours[4], (std::vector<int>{3, 5}));
  EXPECT_NEAR(g.distances[0][0], 0.01, 1e-15);
  ASSERT_EQ(g.edges.cols(), 12);
  Eigen::Index e = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j : g.neighbours[i]) {
      EXPECT_EQ(g.edges.col(e), Eigen::Vector2i(i, j));
      ++e;
    }
  }
  // At 1.01 cm vertex 1 reaches 0 (1 cm) but not 2 (√2 cm along the edge, 2 cm via 0).
  const GeodesicNeighbours small = geodesic_neighbours(m, {0.0101, 0});
  EXPECT_EQ(small.neighbours[1], (std::vector<int>{0}));
}

TEST(GeodesicNeighbours, RejectsBadInput) {
  const Mesh m = st::tetrahedron();
  st::expect_error<GeometryError>([&] { geodesic_neighbours(m, {0.0}); },
                                       {"geodesic_neighbours", "radius", "> 0"});
  st::expect_error<GeometryError>([&] { geodesic_neighbours(m, {-0.06}); },
                                       {"geodesic_neighbours", "radius"});
  st::expect_error<GeometryError>([&] { geodesic_neighbours(m, {std::nan("")}); },
                                       {"geodesic_neighbours", "radius"});
  st::expect_error<GeometryError>([&] { geodesic_neighbours(m, {0.06, -1}); },
                                       {"geodesic_neighbours", "max_neighbours", "-1"});
  st::expect_error<GeometryError>([] { geodesic_neighbours(Mesh{}); },
                                       {"geodesic_neighbours", "no vertices"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace

#include "framework/geometry/geodesic_neighbours.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

#include "framework/geometry/one_ring.hpp"

namespace skinlab::geometry {
namespace {

// The edge graph in compressed rows: neighbours of i are adj[offset[i] .. offset[i+1]).
struct EdgeGraph {
  std::vector<int> offset, adj;
  std::vector<double> length;
};

EdgeGraph edge_graph(const Mesh& mesh) {
  const OneRing ring = one_ring(mesh);
  EdgeGraph g;
  g.offset.resize(ring.neighbours.size() + 1, 0);
  for (size_t i = 0; i < ring.neighbours.size(); ++i) {
    g.offset[i + 1] = g.offset[i] + static_cast<int>(ring.neighbours[i].size());
  }
  g.adj.reserve(static_cast<size_t>(g.offset.back()));
  g.length.reserve(static_cast<size_t>(g.offset.back()));
  for (size_t i = 0; i < ring.neighbours.size(); ++i) {
    for (int j : ring.neighbours[i]) {
      g.adj.push_back(j);
      g.length.push_back((mesh.V.row(static_cast<Eigen::Index>(i)) - mesh.V.row(j)).norm());
    }
  }
  return g;
}

// Per-thread Dijkstra state; `dist` stays at +inf outside the vertices touched by one search.
struct Scratch {
  std::vector<double> dist;
  std::vector<int> touched;
  std::priority_queue<std::pair<double, int>, std::vector<std::pair<double, int>>,
                      std::greater<>>
      heap;
};

// SplitMix64 (Steele et al. 2014): a portable generator, unlike std::shuffle and the std
// distributions, whose algorithms differ between standard libraries.
uint64_t splitmix64(uint64_t& state) {
  uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// Unbiased integer in [0, n) by rejection.
uint64_t uniform_below(uint64_t n, uint64_t& state) {
  const uint64_t limit = std::numeric_limits<uint64_t>::max() - std::numeric_limits<uint64_t>::max() % n;
  uint64_t x;
  do x = splitmix64(state);
  while (x >= limit);
  return x % n;
}

// `ball` is sorted by (distance, index); keeps `cap` of them by the chosen rule, still sorted.
void apply_cap(std::vector<std::pair<double, int>>& ball, const GeodesicOptions& options,
               int vertex) {
  const size_t n = ball.size(), cap = static_cast<size_t>(options.max_neighbours);
  if (cap == 0 || n <= cap) return;
  switch (options.cap) {
    case NeighbourCap::kNearest:
      ball.resize(cap);
      return;
    case NeighbourCap::kStratified: {
      for (size_t k = 0; k < cap; ++k) ball[k] = ball[(2 * k + 1) * n / (2 * cap)];
      ball.resize(cap);
      return;
    }
    case NeighbourCap::kRandom: {
      uint64_t state = options.seed ^ (0xd1b54a32d192ed03ull * (static_cast<uint64_t>(vertex) + 1));
      for (size_t k = 0; k < cap; ++k) {  // partial Fisher–Yates
        std::swap(ball[k], ball[k + uniform_below(n - k, state)]);
      }
      ball.resize(cap);
      std::sort(ball.begin(), ball.end());
      return;
    }
  }
}

}  // namespace

GeodesicNeighbours geodesic_neighbours(const Mesh& mesh, const GeodesicOptions& options) {
  mesh.validate("geodesic_neighbours");
  if (!std::isfinite(options.radius) || options.radius <= 0) {
    throw GeometryError("geodesic_neighbours: radius must be finite and > 0, got " +
                        std::to_string(options.radius));
  }
  if (options.max_neighbours < 0) {
    throw GeometryError("geodesic_neighbours: max_neighbours must be >= 0 (0: no cap), got " +
                        std::to_string(options.max_neighbours));
  }
  const EdgeGraph g = edge_graph(mesh);
  const int nv = mesh.num_vertices();
  const double radius = options.radius;

  GeodesicNeighbours out;
  out.neighbours.resize(static_cast<size_t>(nv));
  out.distances.resize(static_cast<size_t>(nv));
  out.ball_size.resize(nv);

  tbb::enumerable_thread_specific<Scratch> scratch([nv] {
    Scratch s;
    s.dist.assign(static_cast<size_t>(nv), std::numeric_limits<double>::infinity());
    return s;
  });
  tbb::parallel_for(tbb::blocked_range<int>(0, nv, 16), [&](const tbb::blocked_range<int>& range) {
    Scratch& s = scratch.local();
    std::vector<std::pair<double, int>> ball;
    for (int source = range.begin(); source != range.end(); ++source) {
      ball.clear();
      s.dist[static_cast<size_t>(source)] = 0;
      s.touched.push_back(source);
      s.heap.emplace(0.0, source);
      while (!s.heap.empty()) {
        const auto [d, u] = s.heap.top();
        s.heap.pop();
        if (d > s.dist[static_cast<size_t>(u)]) continue;  // stale entry
        if (u != source) ball.emplace_back(d, u);
        for (int e = g.offset[static_cast<size_t>(u)]; e < g.offset[static_cast<size_t>(u) + 1];
             ++e) {
          const int w = g.adj[static_cast<size_t>(e)];
          const double nd = d + g.length[static_cast<size_t>(e)];
          // Only paths inside the ball are explored: this bound is what makes the search local.
          if (nd <= radius && nd < s.dist[static_cast<size_t>(w)]) {
            if (s.dist[static_cast<size_t>(w)] == std::numeric_limits<double>::infinity()) {
              s.touched.push_back(w);
            }
            s.dist[static_cast<size_t>(w)] = nd;
            s.heap.emplace(nd, w);
          }
        }
      }
      for (int t : s.touched) s.dist[static_cast<size_t>(t)] = std::numeric_limits<double>::infinity();
      s.touched.clear();

      std::sort(ball.begin(), ball.end());  // (distance, index): ties broken by index
      out.ball_size(source) = static_cast<int>(ball.size());
      apply_cap(ball, options, source);
      auto& ids = out.neighbours[static_cast<size_t>(source)];
      auto& dists = out.distances[static_cast<size_t>(source)];
      ids.resize(ball.size());
      dists.resize(ball.size());
      for (size_t k = 0; k < ball.size(); ++k) {
        dists[k] = ball[k].first;
        ids[k] = ball[k].second;
      }
    }
  });

  Eigen::Index total = 0;
  for (const auto& list : out.neighbours) total += static_cast<Eigen::Index>(list.size());
  out.edges.resize(2, total);
  Eigen::Index e = 0;
  for (int i = 0; i < nv; ++i) {
    for (int j : out.neighbours[static_cast<size_t>(i)]) {
      out.edges(0, e) = i;
      out.edges(1, e) = j;
      ++e;
    }
  }
  return out;
}

}  // namespace skinlab::geometry

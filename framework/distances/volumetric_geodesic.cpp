#include "framework/distances/volumetric_geodesic.hpp"

#include "framework/distances/triangle_tree.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "framework/core/registry.hpp"
#include "framework/core/timing.hpp"
#include "framework/geometry/closest_point_on_segment.hpp"

namespace skinlab::distances {

namespace {

using aabb::Point;
using aabb::Segment;

constexpr double kInf = std::numeric_limits<double>::infinity();
const char* const kOwner = "distance 'volumetric_geodesic'";

/// Undirected mesh-edge graph in CSR form, with edge lengths and connected components.
struct SurfaceGraph {
  std::vector<int> offsets;  ///< #V+1
  std::vector<int> targets;  ///< 2·#E
  std::vector<double> lengths;
  std::vector<int> component;  ///< #V component id
  int num_components = 0;
};

SurfaceGraph build_graph(const geometry::Mesh& mesh) {
  const int nv = mesh.num_vertices();
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * static_cast<std::size_t>(mesh.num_faces()));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      if (a != b) edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());

  SurfaceGraph g;
  g.offsets.assign(nv + 1, 0);
  for (const auto& [a, b] : edges) {
    ++g.offsets[a + 1];
    ++g.offsets[b + 1];
  }
  for (int v = 0; v < nv; ++v) g.offsets[v + 1] += g.offsets[v];
  g.targets.resize(g.offsets[nv]);
  g.lengths.resize(g.offsets[nv]);
  std::vector<int> fill(g.offsets.begin(), g.offsets.end() - 1);
  for (const auto& [a, b] : edges) {
    const double length = (mesh.V.row(a) - mesh.V.row(b)).norm();
    g.targets[fill[a]] = b;
    g.lengths[fill[a]++] = length;
    g.targets[fill[b]] = a;
    g.lengths[fill[b]++] = length;
  }

  g.component.assign(nv, -1);
  std::vector<int> stack;
  for (int s = 0; s < nv; ++s) {
    if (g.component[s] >= 0) continue;
    g.component[s] = g.num_components;
    stack.push_back(s);
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      for (int e = g.offsets[v]; e < g.offsets[v + 1]; ++e) {
        if (g.component[g.targets[e]] < 0) {
          g.component[g.targets[e]] = g.num_components;
          stack.push_back(g.targets[e]);
        }
      }
    }
    ++g.num_components;
  }
  return g;
}

/// Closest point of bone [a, b] to p; a bone with |b−a|² < 1e-8 is its joint (RigNet's rule).
Eigen::Vector3d project_on_bone(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b) {
  return geometry::closest_point_on_segment(p, a, b, 1e-8);
}

/// numpy.percentile's default (linear interpolation between order statistics); sorts `x`.
double percentile(std::vector<double>& x, double q) {
  std::sort(x.begin(), x.end());
  const double rank = q / 100.0 * static_cast<double>(x.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(rank));
  const std::size_t hi = std::min(lo + 1, x.size() - 1);
  return x[lo] + (x[hi] - x[lo]) * (rank - static_cast<double>(lo));
}

/// Per-thread scratch of the Dijkstra stage: O(#V + #components), reused across bones.
struct Scratch {
  std::vector<double> direct, label, best_seed_distance;
  std::vector<int> best_seed;
  std::vector<std::pair<double, int>> heap;
  std::vector<std::pair<double, int>> candidates;  // visibility stage: (distance, sample)
};

/// Dijkstra on `label` from every vertex already in `heap` (lazy deletion of stale entries).
void dijkstra(const SurfaceGraph& g, std::vector<double>& label,
              std::vector<std::pair<double, int>>& heap) {
  const auto cmp = std::greater<std::pair<double, int>>();
  std::make_heap(heap.begin(), heap.end(), cmp);
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), cmp);
    const auto [d, v] = heap.back();
    heap.pop_back();
    if (d > label[v]) continue;
    for (int e = g.offsets[v]; e < g.offsets[v + 1]; ++e) {
      const int w = g.targets[e];
      const double dw = d + g.lengths[e];
      if (dw < label[w]) {
        label[w] = dw;
        heap.emplace_back(dw, w);
        std::push_heap(heap.begin(), heap.end(), cmp);
      }
    }
  }
}

}  // namespace

VolumetricGeodesic::Options VolumetricGeodesic::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, kOwner);
  f.optional("samples_per_bone", o.samples_per_bone)
      .check(o.samples_per_bone >= 2, "samples_per_bone", "must be at least 2");
  f.optional("ray_epsilon", o.ray_epsilon)
      .check(std::isfinite(o.ray_epsilon) && o.ray_epsilon > 0, "ray_epsilon",
             "must be positive");
  f.optional("filter_far_visible", o.filter_far_visible);
  f.optional("filter_percentile", o.filter_percentile)
      .check(o.filter_percentile >= 0 && o.filter_percentile <= 100, "filter_percentile",
             "must be in [0, 100]");
  f.optional("filter_factor", o.filter_factor)
      .check(std::isfinite(o.filter_factor) && o.filter_factor >= 1, "filter_factor",
             "must be at least 1");
  f.optional("unreached", o.unreached)
      .check(o.unreached == "restart" || o.unreached == "euclidean", "unreached",
             "must be 'restart' or 'euclidean', got '" + o.unreached + "'");
  f.optional("unreached_penalty", o.unreached_penalty)
      .check(std::isfinite(o.unreached_penalty) && o.unreached_penalty >= 0,
             "unreached_penalty", "must be finite and non-negative");
  f.finish();
  return o;
}

Eigen::MatrixXd VolumetricGeodesic::compute(const geometry::Mesh& mesh,
                                            const geometry::Skeleton& skeleton,
                                            VolumetricGeodesicTimings* timings) const {
  mesh.validate(kOwner);
  skeleton.validate(kOwner);
  const auto bones = skeleton.bones();
  const int nv = mesh.num_vertices();
  const int nb = static_cast<int>(bones.size());
  VolumetricGeodesicTimings local_timings;
  VolumetricGeodesicTimings& t = timings ? *timings : local_timings;

  // ---- stage 1: AABB tree over the non-degenerate triangles, surface graph ------------------
  auto start = std::chrono::steady_clock::now();
  const aabb::TriangleTree triangles(mesh);  // built now: concurrent queries below never build
  const aabb::Tree& tree = triangles.tree();
  const SurfaceGraph graph = build_graph(mesh);
  t.aabb = seconds_since(start);

  struct BoneEnds {
    Eigen::Vector3d a, b;
    std::vector<Eigen::Vector3d> samples;
  };
  std::vector<BoneEnds> ends(nb);
  for (int i = 0; i < nb; ++i) {
    ends[i].a = skeleton.positions.row(bones[i].start).transpose();
    ends[i].b = skeleton.bone_end(bones[i]);
    if ((ends[i].b - ends[i].a).squaredNorm() < 1e-8) {
      ends[i].samples = {ends[i].a};
    } else {
      const int n = options_.samples_per_bone;
      for (int s = 0; s < n; ++s) {
        const double u = static_cast<double>(s) / (n - 1);
        ends[i].samples.push_back((1 - u) * ends[i].a + u * ends[i].b);
      }
    }
  }
  const auto bone_distance = [&](int v, int b) {
    const Eigen::Vector3d p = mesh.V.row(v).transpose();
    return (p - project_on_bone(p, ends[b].a, ends[b].b)).norm();
  };

  // ---- stage 2: visibility. D(v, b) = distance to the nearest ray origin that sees v, or ∞ ---
  start = std::chrono::steady_clock::now();
  Eigen::MatrixXd D(nv, nb);
  tbb::enumerable_thread_specific<Scratch> scratch;
  const double eps = options_.ray_epsilon;
  const auto sees = [&](const Eigen::Vector3d& origin, const Eigen::Vector3d& target) {
    const Eigen::Vector3d dir = target - origin;
    const double length = dir.norm();
    if (length <= eps) return true;
    const Eigen::Vector3d stop = target - dir * (eps / length);
    return !tree.do_intersect(Segment(Point(origin.x(), origin.y(), origin.z()),
                                      Point(stop.x(), stop.y(), stop.z())));
  };
  // Work items are (bone, block of vertices), so a one-bone skeleton still uses every thread.
  constexpr int kBlock = 256;
  const int blocks = (nv + kBlock - 1) / kBlock;
  tbb::parallel_for(tbb::blocked_range<int>(0, nb * blocks), [&](const tbb::blocked_range<int>& r) {
    auto& candidates = scratch.local().candidates;
    for (int item = r.begin(); item != r.end(); ++item) {
      const int b = item / blocks;
      const int v_end = std::min(nv, (item % blocks + 1) * kBlock);
      const auto& samples = ends[b].samples;
      for (int v = (item % blocks) * kBlock; v < v_end; ++v) {
        const Eigen::Vector3d p = mesh.V.row(v).transpose();
        // RigNet's origin, the projection, is the nearest point of the bone, so it goes first;
        // then the samples by distance: the first that sees v gives the minimum.
        const Eigen::Vector3d projection = project_on_bone(p, ends[b].a, ends[b].b);
        double d = kInf;
        if (sees(projection, p)) {
          d = (p - projection).norm();
        } else {
          candidates.clear();
          for (int s = 0; s < static_cast<int>(samples.size()); ++s) {
            if ((samples[s] - projection).squaredNorm() > 1e-24) {
              candidates.emplace_back((samples[s] - p).norm(), s);
            }
          }
          std::sort(candidates.begin(), candidates.end());
          for (const auto& [ds, s] : candidates) {
            if (sees(samples[s], p)) {
              d = ds;
              break;
            }
          }
        }
        D(v, b) = d;
      }
    }
  });
  if (options_.filter_far_visible) {
    tbb::parallel_for(0, nb, [&](int b) {
      std::vector<double> visible;
      for (int v = 0; v < nv; ++v) {
        if (std::isfinite(D(v, b))) visible.push_back(D(v, b));
      }
      if (visible.empty()) return;
      const double threshold = options_.filter_factor * percentile(visible, options_.filter_percentile);
      for (int v = 0; v < nv; ++v) {
        if (D(v, b) > threshold) D(v, b) = kInf;
      }
    });
  }
  t.visibility = seconds_since(start);

  // ---- stage 3: per bone, one multi-source Dijkstra from the visible vertices ---------------
  start = std::chrono::steady_clock::now();
  const bool restart = options_.unreached == "restart";
  const double penalty = options_.unreached_penalty;
  tbb::parallel_for(0, nb, [&](int b) {
    Scratch& s = scratch.local();
    s.direct.assign(D.col(b).data(), D.col(b).data() + nv);
    s.label = s.direct;
    s.heap.clear();
    for (int v = 0; v < nv; ++v) {
      if (std::isfinite(s.label[v])) s.heap.emplace_back(s.label[v], v);
    }
    dijkstra(graph, s.label, s.heap);

    // Dijkstra fills whole components, so an infinite label means a component with no seed.
    if (restart) {
      s.best_seed.assign(graph.num_components, -1);
      s.best_seed_distance.assign(graph.num_components, kInf);
      for (int v = 0; v < nv; ++v) {
        if (std::isfinite(s.label[v])) continue;
        const int c = graph.component[v];
        const double d = bone_distance(v, b);
        if (d < s.best_seed_distance[c]) {
          s.best_seed_distance[c] = d;
          s.best_seed[c] = v;
        }
      }
      s.heap.clear();
      for (int c = 0; c < graph.num_components; ++c) {
        if (s.best_seed[c] < 0) continue;
        s.label[s.best_seed[c]] = penalty + s.best_seed_distance[c];
        s.heap.emplace_back(s.label[s.best_seed[c]], s.best_seed[c]);
      }
      dijkstra(graph, s.label, s.heap);
    } else {
      for (int v = 0; v < nv; ++v) {
        if (!std::isfinite(s.label[v])) s.label[v] = penalty + bone_distance(v, b);
      }
    }
    // As RigNet: a visible vertex keeps its straight-line distance even where a surface
    // route from another visible vertex would be shorter.
    for (int v = 0; v < nv; ++v) D(v, b) = std::isfinite(s.direct[v]) ? s.direct[v] : s.label[v];
  });
  t.dijkstra = seconds_since(start);

  for (int b = 0; b < nb; ++b) {
    for (int v = 0; v < nv; ++v) {
      if (!std::isfinite(D(v, b))) {
        throw geometry::GeometryError(std::string(kOwner) + ": no finite distance from vertex " +
                                      std::to_string(v) + " to bone " + std::to_string(b) +
                                      " (" + skeleton.names[bones[b].start] + " -> " +
                                      skeleton.names[bones[b].end] + ")");
      }
    }
  }
  return D;
}

}  // namespace skinlab::distances

SKINLAB_REGISTER(distance, volumetric_geodesic, skinlab::distances::VolumetricGeodesic);

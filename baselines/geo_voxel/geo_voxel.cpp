#include "baselines/geo_voxel/geo_voxel.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <string>
#include <utility>

#include "framework/core/registry.hpp"
#include "framework/geometry/closest_point_on_segment.hpp"
#include "framework/geometry/orient_outward.hpp"

namespace skinlab::baselines {

namespace {

using geometry::GeometryError;

constexpr double kInf = std::numeric_limits<double>::infinity();
const char* const kGeoVoxelOwner = "binder 'geo_voxel'";

/// Offsets, in cells, of the ray lines from the cell centres along the two axes across a line:
/// irrational-looking multiples of 1e-4 so that no line meets a vertex or edge of a test mesh
/// whose coordinates are round numbers; far below any cell size that matters.
constexpr double kLineJitter[3] = {1.2345e-4, 0.7071e-4, 0.9183e-4};

/// Margin of empty cells around the character (VoxelGrid requires ≥ 1; more buys nothing here,
/// since paths never leave the solid).
constexpr int kMarginCells = 1;

/// A hit of a grid line with a triangle: coordinate along the line and whether the triangle's
/// normal points along +axis.
struct Hit {
  double t;
  bool facing_plus;
  bool operator<(const Hit& o) const { return t < o.t; }
};

/// 26 neighbour offsets of the padded grid and their lengths in cells.
struct Neighbours {
  std::array<int, 26> offset;
  std::array<double, 26> length;
};

Neighbours neighbours(const geometry::VoxelGrid& grid) {
  Neighbours n{};
  const int sy = grid.index(0, 1, 0) - grid.index(0, 0, 0);
  const int sz = grid.index(0, 0, 1) - grid.index(0, 0, 0);
  int k = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        n.offset[k] = dx + sy * dy + sz * dz;
        n.length[k] = std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz));
        ++k;
      }
  return n;
}

/// Per-thread Dijkstra buffers, reused from bone to bone.
struct Scratch {
  std::vector<double> dist;  ///< per padded cell, in cells; +∞ when unreached
  std::vector<int> touched;
  std::vector<std::pair<double, int>> heap;
  std::vector<int> seeds;
};

}  // namespace

std::vector<VoxelState> solid_voxels(const geometry::Mesh& mesh,
                                     const geometry::SurfaceVoxels& surface) {
  const auto& grid = surface.grid();
  const auto& dims = grid.dims();
  const double s = grid.cell_size();
  const Eigen::Vector3d& origin = grid.origin();
  std::vector<VoxelState> state(grid.num_padded(), VoxelState::kExterior);
  // votes[cell]: number of axes whose rule says "inside".
  std::vector<std::uint8_t> votes(grid.num_padded(), 0);

  std::vector<std::vector<Hit>> lines;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    const int nb = dims[b], nc = dims[c];
    lines.assign(static_cast<std::size_t>(nb) * nc, {});
    // Line (j, k) runs along a through u_b = origin_b + (j + ½ + jitter_b) s, likewise c.
    const auto line_coord = [&](int axis, int j) {
      return origin[axis] + (j + 0.5 + kLineJitter[axis]) * s;
    };
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const Eigen::Vector3d p0 = mesh.V.row(mesh.F(f, 0)), p1 = mesh.V.row(mesh.F(f, 1)),
                            p2 = mesh.V.row(mesh.F(f, 2));
      const Eigen::Vector3d n = (p1 - p0).cross(p2 - p0);
      if (n[a] == 0) continue;  // parallel to the lines (or degenerate): no crossing
      const double lo_b = std::min({p0[b], p1[b], p2[b]}), hi_b = std::max({p0[b], p1[b], p2[b]});
      const double lo_c = std::min({p0[c], p1[c], p2[c]}), hi_c = std::max({p0[c], p1[c], p2[c]});
      const int j0 = std::max(0, static_cast<int>(std::ceil((lo_b - origin[b]) / s - 0.5 -
                                                           kLineJitter[b])));
      const int j1 = std::min(nb - 1, static_cast<int>(std::floor((hi_b - origin[b]) / s - 0.5 -
                                                                kLineJitter[b])));
      const int k0 = std::max(0, static_cast<int>(std::ceil((lo_c - origin[c]) / s - 0.5 -
                                                           kLineJitter[c])));
      const int k1 = std::min(nc - 1, static_cast<int>(std::floor((hi_c - origin[c]) / s - 0.5 -
                                                                kLineJitter[c])));
      for (int k = k0; k <= k1; ++k) {
        const double uc = line_coord(c, k);
        for (int j = j0; j <= j1; ++j) {
          const double ub = line_coord(b, j);
          // 2D edge functions in the (b, c) plane; the point is inside when all three have the
          // sign of the projected area (n[a]).
          const auto edge = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
            return (q[b] - p[b]) * (uc - p[c]) - (q[c] - p[c]) * (ub - p[b]);
          };
          const double e0 = edge(p0, p1), e1 = edge(p1, p2), e2 = edge(p2, p0);
          const bool inside = n[a] > 0 ? (e0 >= 0 && e1 >= 0 && e2 >= 0)
                                       : (e0 <= 0 && e1 <= 0 && e2 <= 0);
          if (!inside) continue;
          // Plane n·(x − p0) = 0 solved for x_a on the line.
          const double t = p0[a] - (n[b] * (ub - p0[b]) + n[c] * (uc - p0[c])) / n[a];
          lines[static_cast<std::size_t>(k) * nb + j].push_back({t, n[a] > 0});
        }
      }
    }
    for (int k = 0; k < nc; ++k) {
      for (int j = 0; j < nb; ++j) {
        auto& hits = lines[static_cast<std::size_t>(k) * nb + j];
        if (hits.empty()) continue;
        std::sort(hits.begin(), hits.end());
        std::size_t next = 0;  // first hit above the current cell centre
        for (int i = 0; i < dims[a]; ++i) {
          const double centre = origin[a] + (i + 0.5) * s;
          while (next < hits.size() && hits[next].t <= centre) ++next;
          // Along +a the first surface seen is hits[next]: a back face (normal along +a) means
          // the cell is inside; along −a it is hits[next − 1], a back face when its normal
          // points along −a.
          const bool plus = next < hits.size() && hits[next].facing_plus;
          const bool minus = next > 0 && !hits[next - 1].facing_plus;
          if (plus || minus) {
            std::array<int, 3> cell{};
            cell[a] = i;
            cell[b] = j;
            cell[c] = k;
            ++votes[grid.index(cell[0], cell[1], cell[2])];
          }
        }
      }
    }
  }
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) {
        const int cell = grid.index(i, j, k);
        if (surface.is_mesh(cell)) {
          state[cell] = VoxelState::kBoundary;
        } else if (votes[cell] >= 2) {
          state[cell] = VoxelState::kInterior;
        }
      }
  return state;
}

GeoVoxel::Options GeoVoxel::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, kGeoVoxelOwner);
  f.optional("resolution", o.resolution)
      .check(o.resolution >= 8, "resolution", "must be at least 8")
      .check(o.resolution <= 1024, "resolution", "must be at most 1024");
  f.optional("falloff", o.falloff)
      .check(std::isfinite(o.falloff) && o.falloff >= 0 && o.falloff <= 1, "falloff",
             "must be in [0, 1]");
  f.optional("max_influences", o.max_influences)
      .check(o.max_influences >= 1, "max_influences", "must be at least 1");
  f.optional("orient_outward", o.orient_outward);
  f.finish();
  return o;
}

Eigen::MatrixXd GeoVoxel::distances(const geometry::Mesh& input,
                                    const geometry::Skeleton& skeleton,
                                    GeoVoxelStats* stats) const {
  input.validate(kGeoVoxelOwner);
  skeleton.validate(kGeoVoxelOwner);
  geometry::OrientReport orient;
  const geometry::Mesh mesh =
      options_.orient_outward ? geometry::orient_outward(input, &orient) : input;
  const auto bones = skeleton.bones();
  const int nv = mesh.num_vertices();
  const int nb = static_cast<int>(bones.size());
  GeoVoxelStats local_stats;
  GeoVoxelStats& st = stats ? *stats : local_stats;
  st = {};
  st.flipped_parts = orient.flipped_parts;

  const auto surface = geometry::SurfaceVoxels::voxelize(
      mesh, geometry::VoxelGrid::fit(mesh, skeleton, options_.resolution, kMarginCells));
  const auto& grid = surface.grid();
  const std::vector<VoxelState> state = solid_voxels(mesh, surface);
  std::vector<int> solid_cells;
  for (int c = 0; c < grid.num_padded(); ++c) {
    if (state[c] == VoxelState::kInterior) ++st.interior_voxels;
    if (state[c] == VoxelState::kBoundary) ++st.boundary_voxels;
    if (state[c] != VoxelState::kExterior) solid_cells.push_back(c);
  }
  const auto solid = [&](int c) { return state[c] != VoxelState::kExterior; };
  const Neighbours nbr = neighbours(grid);
  const double s = grid.cell_size();

  // Offset of every vertex from its voxel centre, in cells.
  const auto& vertex_cells = surface.vertex_cells();
  Eigen::VectorXd offset(nv);
  for (int v = 0; v < nv; ++v) {
    offset[v] = (mesh.V.row(v).transpose() - grid.center(vertex_cells[v])).norm() / s;
  }

  Eigen::MatrixXd D(nv, nb);
  std::vector<int> snapped(nb, 0);
  tbb::enumerable_thread_specific<Scratch> scratch;
  tbb::parallel_for(0, nb, [&](int b) {
    Scratch& sc = scratch.local();
    if (sc.dist.empty()) sc.dist.assign(grid.num_padded(), kInf);
    for (int c : sc.touched) sc.dist[c] = kInf;
    sc.touched.clear();
    sc.heap.clear();
    const Eigen::Vector3d a = skeleton.positions.row(bones[b].start).transpose();
    const Eigen::Vector3d e = skeleton.bone_end(bones[b]);
    grid.overlapping_cells(a, e, e, sc.seeds);
    for (int c : sc.seeds) {
      if (!solid(c)) continue;
      sc.dist[c] = 0;
      sc.touched.push_back(c);
      sc.heap.emplace_back(0.0, c);
    }
    if (sc.heap.empty()) {  // an out-of-body bone: start at the nearest solid voxel
      snapped[b] = 1;
      double best = kInf;
      int best_cell = -1;
      for (int c : solid_cells) {
        const double d = geometry::point_segment_distance(grid.center(c), a, e);
        if (d < best) best = d, best_cell = c;
      }
      if (best_cell >= 0) {
        sc.dist[best_cell] = best / s;
        sc.touched.push_back(best_cell);
        sc.heap.emplace_back(best / s, best_cell);
      }
    }
    const auto cmp = std::greater<std::pair<double, int>>();
    std::make_heap(sc.heap.begin(), sc.heap.end(), cmp);
    while (!sc.heap.empty()) {
      std::pop_heap(sc.heap.begin(), sc.heap.end(), cmp);
      const auto [d, c] = sc.heap.back();
      sc.heap.pop_back();
      if (d > sc.dist[c]) continue;
      for (int k = 0; k < 26; ++k) {
        const int n = c + nbr.offset[k];
        if (!solid(n)) continue;  // padding is exterior, so no bounds check is needed
        const double dn = d + nbr.length[k];
        if (dn < sc.dist[n]) {
          if (sc.dist[n] == kInf) sc.touched.push_back(n);
          sc.dist[n] = dn;
          sc.heap.emplace_back(dn, n);
          std::push_heap(sc.heap.begin(), sc.heap.end(), cmp);
        }
      }
    }
    for (int v = 0; v < nv; ++v) D(v, b) = (sc.dist[vertex_cells[v]] + offset[v]) * s;
  });
  st.snapped_bones = std::accumulate(snapped.begin(), snapped.end(), 0);

  for (int v = 0; v < nv; ++v) {
    if (D.row(v).minCoeff() < kInf) continue;
    ++st.euclidean_vertices;
    const Eigen::Vector3d p = mesh.V.row(v).transpose();
    for (int b = 0; b < nb; ++b) {
      D(v, b) = geometry::point_segment_distance(p, skeleton.positions.row(bones[b].start),
                                                 skeleton.bone_end(bones[b]));
    }
  }
  return D;
}

Eigen::MatrixXd GeoVoxel::bind(const geometry::Mesh& mesh, const geometry::Skeleton& skeleton,
                               GeoVoxelStats* stats) const {
  const Eigen::MatrixXd D = distances(mesh, skeleton, stats);
  const int nv = static_cast<int>(D.rows()), nb = static_cast<int>(D.cols());
  Eigen::Vector3d lo = mesh.V.colwise().minCoeff(), hi = mesh.V.colwise().maxCoeff();
  lo = lo.cwiseMin(skeleton.positions.colwise().minCoeff().transpose());
  hi = hi.cwiseMax(skeleton.positions.colwise().maxCoeff().transpose());
  const double L = (hi - lo).maxCoeff();
  const double alpha = options_.falloff;
  const int keep = std::min(options_.max_influences, nb);

  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(nv, nb);
  std::vector<int> order(nb);
  for (int v = 0; v < nv; ++v) {
    std::iota(order.begin(), order.end(), 0);
    std::partial_sort(order.begin(), order.begin() + keep, order.end(), [&](int i, int j) {
      return D(v, i) < D(v, j) || (D(v, i) == D(v, j) && i < j);
    });
    double sum = 0;
    for (int k = 0; k < keep; ++k) {
      const int b = order[k];
      if (!std::isfinite(D(v, b))) break;  // sorted: the rest is unreached too
      const double d = std::max(D(v, b) / L, 1e-9);
      const double w = 1.0 / ((1 - alpha) * d + alpha * d * d);
      W(v, b) = w * w;
      sum += W(v, b);
    }
    if (!(sum > 0) || !std::isfinite(sum)) {
      throw GeometryError(std::string(kGeoVoxelOwner) + ": vertex " + std::to_string(v) +
                          " has no finite bone weight");
    }
    W.row(v) /= sum;
  }
  return W;
}

}  // namespace skinlab::baselines

SKINLAB_REGISTER(binder, geo_voxel, skinlab::baselines::GeoVoxel);

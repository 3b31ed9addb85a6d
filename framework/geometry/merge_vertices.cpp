#include "framework/geometry/merge_vertices.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

namespace skinlab::geometry {
namespace {

template <class T>
struct TripleHash {
  size_t operator()(const std::array<T, 3>& key) const {
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (const T& x : key) {
      uint64_t bits = 0;
      std::memcpy(&bits, &x, sizeof(T));
      h ^= bits + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    }
    return static_cast<size_t>(h);
  }
};

using Cell = std::array<int64_t, 3>;

// Exact mode: the key is the position itself. Adding +0.0 turns −0.0 into +0.0, so a mirrored
// seam at x = 0 still merges; NaN cannot occur (validate() rejects it).
Eigen::VectorXi merge_exact(const Eigen::MatrixXd& V, std::vector<int>& representatives) {
  std::unordered_map<std::array<double, 3>, int, TripleHash<double>> first;
  first.reserve(static_cast<size_t>(V.rows()));
  Eigen::VectorXi old_to_new(V.rows());
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const std::array<double, 3> key{V(v, 0) + 0.0, V(v, 1) + 0.0, V(v, 2) + 0.0};
    const auto [it, inserted] = first.try_emplace(key, static_cast<int>(representatives.size()));
    if (inserted) representatives.push_back(static_cast<int>(v));
    old_to_new(v) = it->second;
  }
  return old_to_new;
}

// Tolerance mode: a uniform grid with cells of the tolerance's size, so every representative
// within reach lies in the 27 cells around the vertex. Among those within reach the one with the
// smallest new index wins, which makes the result independent of hash iteration order.
Eigen::VectorXi merge_within(const Eigen::MatrixXd& V, double tolerance,
                             std::vector<int>& representatives) {
  constexpr double kMaxCell = 4e18;  // below 2^62, so cell ± 1 cannot overflow
  std::unordered_map<Cell, std::vector<int>, TripleHash<int64_t>> grid;
  grid.reserve(static_cast<size_t>(V.rows()));
  Eigen::VectorXi old_to_new(V.rows());
  const double tol2 = tolerance * tolerance;
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    Cell cell;
    for (int k = 0; k < 3; ++k) {
      const double c = std::floor(V(v, k) / tolerance);
      if (!(std::abs(c) < kMaxCell)) {
        throw GeometryError("merge_vertices: tolerance " + std::to_string(tolerance) +
                            " is too small for the coordinates of vertex " + std::to_string(v));
      }
      cell[k] = static_cast<int64_t>(c);
    }
    int best = std::numeric_limits<int>::max();
    for (int64_t dx = -1; dx <= 1; ++dx) {
      for (int64_t dy = -1; dy <= 1; ++dy) {
        for (int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
          if (it == grid.end()) continue;
          for (int n : it->second) {
            if (n < best && (V.row(representatives[n]) - V.row(v)).squaredNorm() <= tol2) best = n;
          }
        }
      }
    }
    if (best == std::numeric_limits<int>::max()) {
      best = static_cast<int>(representatives.size());
      representatives.push_back(static_cast<int>(v));
      grid[cell].push_back(best);
    }
    old_to_new(v) = best;
  }
  return old_to_new;
}

}  // namespace

MergedMesh merge_vertices(const Mesh& mesh, const MergeOptions& options) {
  mesh.validate("merge_vertices");
  if (!std::isfinite(options.tolerance) || options.tolerance < 0) {
    throw GeometryError("merge_vertices: tolerance must be finite and >= 0, got " +
                        std::to_string(options.tolerance));
  }
  std::vector<int> representatives;  // old index of the first occurrence of every new vertex
  MergedMesh out;
  out.old_to_new = options.tolerance == 0
                       ? merge_exact(mesh.V, representatives)
                       : merge_within(mesh.V, options.tolerance, representatives);

  out.mesh.V.resize(static_cast<Eigen::Index>(representatives.size()), 3);
  for (size_t n = 0; n < representatives.size(); ++n) {
    out.mesh.V.row(static_cast<Eigen::Index>(n)) = mesh.V.row(representatives[n]);
  }

  std::vector<int> kept;
  kept.reserve(static_cast<size_t>(mesh.F.rows()));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const int a = out.old_to_new(mesh.F(f, 0)), b = out.old_to_new(mesh.F(f, 1)),
              c = out.old_to_new(mesh.F(f, 2));
    if (a != b && b != c && c != a) kept.push_back(static_cast<int>(f));
  }
  if (kept.empty()) {
    throw GeometryError("merge_vertices: every one of the " + std::to_string(mesh.F.rows()) +
                        " faces became degenerate after merging (tolerance " +
                        std::to_string(options.tolerance) + ")");
  }
  out.kept_faces = Eigen::Map<const Eigen::VectorXi>(kept.data(), static_cast<Eigen::Index>(kept.size()));
  out.mesh.F.resize(out.kept_faces.size(), 3);
  for (Eigen::Index f = 0; f < out.kept_faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) out.mesh.F(f, k) = out.old_to_new(mesh.F(out.kept_faces(f), k));
  }
  return out;
}

}  // namespace skinlab::geometry

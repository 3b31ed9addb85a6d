#include "framework/geometry/subdivide.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace skinlab::geometry {
namespace {

using RowSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;

uint64_t edge_key(int a, int b) {
  const auto lo = static_cast<uint32_t>(std::min(a, b)), hi = static_cast<uint32_t>(std::max(a, b));
  return (static_cast<uint64_t>(lo) << 32) | hi;
}

int64_t count_edges(const Eigen::MatrixXi& F) {
  std::vector<uint64_t> keys;
  keys.reserve(static_cast<size_t>(3 * F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (a != b) keys.push_back(edge_key(a, b));
    }
  }
  std::sort(keys.begin(), keys.end());
  return std::unique(keys.begin(), keys.end()) - keys.begin();
}

// One 1-to-4 step; `step` receives the #V'×#V interpolation matrix of this step.
Mesh midpoint_step(const Mesh& in, RowSparse& step) {
  const int n = in.num_vertices();
  std::unordered_map<uint64_t, int> midpoint;
  midpoint.reserve(static_cast<size_t>(3 * in.F.rows()));
  std::vector<std::pair<int, int>> parents;  // of each new vertex, in numbering order
  auto mid = [&](int a, int b) {
    if (a == b) return a;
    const auto [it, inserted] =
        midpoint.try_emplace(edge_key(a, b), n + static_cast<int>(parents.size()));
    if (inserted) parents.emplace_back(a, b);
    return it->second;
  };

  Mesh out;
  out.F.resize(4 * in.F.rows(), 3);
  for (Eigen::Index f = 0; f < in.F.rows(); ++f) {
    const int a = in.F(f, 0), b = in.F(f, 1), c = in.F(f, 2);
    const int ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
    out.F.row(4 * f + 0) << a, ab, ca;
    out.F.row(4 * f + 1) << ab, b, bc;
    out.F.row(4 * f + 2) << ca, bc, c;
    out.F.row(4 * f + 3) << ab, bc, ca;
  }

  const int total = n + static_cast<int>(parents.size());
  out.V.resize(total, 3);
  out.V.topRows(n) = in.V;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(n) + 2 * parents.size());
  for (int i = 0; i < n; ++i) entries.emplace_back(i, i, 1.0);
  for (size_t k = 0; k < parents.size(); ++k) {
    const int row = n + static_cast<int>(k);
    const auto [a, b] = parents[k];
    out.V.row(row) = 0.5 * (in.V.row(a) + in.V.row(b));
    entries.emplace_back(row, a, 0.5);
    entries.emplace_back(row, b, 0.5);
  }
  step.resize(total, n);
  step.setFromTriplets(entries.begin(), entries.end());
  return out;
}

}  // namespace

SubdividedMesh subdivide(const Mesh& mesh, const SubdivideOptions& options) {
  mesh.validate("subdivide");
  if (options.min_vertices > options.max_vertices) {
    throw GeometryError("subdivide: min_vertices (" + std::to_string(options.min_vertices) +
                        ") is larger than max_vertices (" + std::to_string(options.max_vertices) +
                        ")");
  }
  SubdividedMesh out;
  out.mesh = mesh;
  out.S.resize(mesh.num_vertices(), mesh.num_vertices());
  out.S.setIdentity();
  while (out.mesh.num_vertices() < options.min_vertices) {
    const int64_t edges = count_edges(out.mesh.F);
    // No edge (all faces index-degenerate) would loop forever without adding a vertex.
    if (edges == 0 || out.mesh.num_vertices() + edges > options.max_vertices) break;
    // 4^levels faces: stop before int overflow of the face matrix' index arithmetic.
    if (out.mesh.F.rows() > (int64_t{1} << 28)) break;
    RowSparse step;
    out.mesh = midpoint_step(out.mesh, step);
    out.S = RowSparse(step * out.S);
    ++out.levels;
  }
  out.S.makeCompressed();
  return out;
}

}  // namespace skinlab::geometry

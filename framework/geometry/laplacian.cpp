#include "framework/geometry/laplacian.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace skinlab::geometry {
namespace {

// One entry (i < j) per face edge; an edge of several faces is summed by setFromTriplets and
// counted once when L is assembled, which is cheaper than sorting the edges here.
std::vector<Eigen::Triplet<double>> uniform_weights(const Mesh& mesh) {
  std::vector<Eigen::Triplet<double>> w;
  w.reserve(static_cast<size_t>(3 * mesh.F.rows()));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      if (a != b) w.emplace_back(std::min(a, b), std::max(a, b), 1.0);
    }
  }
  return w;
}

std::vector<Eigen::Triplet<double>> cotangent_weights(const Mesh& mesh, double degenerate_ratio) {
  std::vector<Eigen::Triplet<double>> w;
  w.reserve(static_cast<size_t>(3 * mesh.F.rows()));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const int idx[3] = {mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)};
    if (idx[0] == idx[1] || idx[1] == idx[2] || idx[2] == idx[0]) continue;
    const Eigen::Vector3d p[3] = {mesh.V.row(idx[0]), mesh.V.row(idx[1]), mesh.V.row(idx[2])};
    const double double_area = (p[1] - p[0]).cross(p[2] - p[0]).norm();
    const double longest2 = std::max({(p[1] - p[0]).squaredNorm(), (p[2] - p[1]).squaredNorm(),
                                      (p[0] - p[2]).squaredNorm()});
    if (!(double_area > degenerate_ratio * longest2)) continue;
    for (int k = 0; k < 3; ++k) {
      // cot of the angle at corner k = (u·v) / |u×v|, |u×v| being the doubled area.
      const int a = idx[(k + 1) % 3], b = idx[(k + 2) % 3];
      const Eigen::Vector3d u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
      w.emplace_back(std::min(a, b), std::max(a, b), 0.5 * u.dot(v) / double_area);
    }
  }
  return w;
}

}  // namespace

Eigen::SparseMatrix<double> laplacian(const Mesh& mesh, const LaplacianOptions& options) {
  mesh.validate("laplacian");
  if (!std::isfinite(options.degenerate_ratio) || options.degenerate_ratio < 0) {
    throw GeometryError("laplacian: degenerate_ratio must be finite and >= 0, got " +
                        std::to_string(options.degenerate_ratio));
  }
  const int n = mesh.num_vertices();
  const bool cot = options.kind == LaplacianKind::kCotangent;
  const auto upper = cot ? cotangent_weights(mesh, options.degenerate_ratio) : uniform_weights(mesh);

  // Sum the per-face terms of each edge first, so clamping acts on the edge's total weight.
  Eigen::SparseMatrix<double, Eigen::RowMajor> A(n, n);
  A.setFromTriplets(upper.begin(), upper.end());

  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(2 * A.nonZeros() + n));
  Eigen::VectorXd degree = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(A, i); it; ++it) {
      // Uniform: an edge weighs 1 however many (non-manifold) faces share it.
      const double a = !cot                    ? 1.0
                       : options.clamp_negative ? std::max(0.0, it.value())
                                                : it.value();
      if (a == 0) continue;
      const int j = static_cast<int>(it.col());
      entries.emplace_back(i, j, -a);
      entries.emplace_back(j, i, -a);
      degree(i) += a;
      degree(j) += a;
    }
  }
  for (int i = 0; i < n; ++i) {
    if (degree(i) != 0) entries.emplace_back(i, i, degree(i));
  }
  Eigen::SparseMatrix<double> L(n, n);
  L.setFromTriplets(entries.begin(), entries.end());
  return L;
}

}  // namespace skinlab::geometry

#pragma once
// Closed tubes (outward-oriented, mirror-symmetric triangulation) for tests of binders and
// deformers: a header without test-framework dependencies, so any test area can use it.

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "framework/geometry/mesh.hpp"

namespace skinlab::testing {

/// Accumulates closed tubes into one mesh (each tube its own connected component).
class TubeBuilder {
 public:
  /// Closed cylinder of radius r from a to b: `rings` rings of `sides` vertices (sides a multiple
  /// of 4), each end closed by a fan around a centre vertex. Outward normals (counter-clockwise
  /// seen from outside). Quads are split so that the mesh is symmetric under the reflection that
  /// maps side j to side sides/2 − j (the plane through the axis and side 0's normal... i.e. the
  /// mirror x → −x for a tube along y or z).
  TubeBuilder& tube(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r, int sides,
                    int rings) {
    const Eigen::Vector3d axis = (b - a).normalized();
    // (u, v, axis) right-handed; u = +x unless the tube runs along x.
    Eigen::Vector3d u = std::abs(axis.x()) > 0.9 ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d(1, 0, 0);
    u = (u - u.dot(axis) * axis).normalized();
    const Eigen::Vector3d v = axis.cross(u);
    const int base = static_cast<int>(V_.size());
    for (int i = 0; i < rings; ++i) {
      const Eigen::Vector3d c = a + (b - a) * i / (rings - 1);
      for (int j = 0; j < sides; ++j) {
        const double t = 2 * M_PI * j / sides;
        V_.push_back(c + r * (std::cos(t) * u + std::sin(t) * v));
      }
    }
    const auto id = [&](int i, int j) { return base + i * sides + (j % sides); };
    const int half = sides / 2;
    for (int i = 0; i + 1 < rings; ++i) {
      for (int j = 0; j < sides; ++j) {
        // Ring i+1 is further along the axis; (j → j+1) turns counter-clockwise about it, so
        // (i,j), (i,j+1), (i+1,j+1) is counter-clockwise seen from outside.
        if (j % half < half / 2) {
          F_.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
          F_.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
        } else {
          F_.push_back({id(i, j), id(i, j + 1), id(i + 1, j)});
          F_.push_back({id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)});
        }
      }
    }
    const int ca = static_cast<int>(V_.size());
    V_.push_back(a);
    const int cb = static_cast<int>(V_.size());
    V_.push_back(b);
    for (int j = 0; j < sides; ++j) {
      F_.push_back({ca, id(0, j + 1), id(0, j)});
      F_.push_back({cb, id(rings - 1, j), id(rings - 1, j + 1)});
    }
    return *this;
  }

  int num_vertices() const { return static_cast<int>(V_.size()); }

  geometry::Mesh build() const {
    geometry::Mesh m;
    m.V.resize(static_cast<Eigen::Index>(V_.size()), 3);
    for (std::size_t k = 0; k < V_.size(); ++k) m.V.row(k) = V_[k];
    m.F.resize(static_cast<Eigen::Index>(F_.size()), 3);
    for (std::size_t k = 0; k < F_.size(); ++k) m.F.row(k) = F_[k];
    return m;
  }

 private:
  std::vector<Eigen::Vector3d> V_;
  std::vector<Eigen::Vector3i> F_;
};

}  // namespace skinlab::testing

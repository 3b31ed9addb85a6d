#pragma once
// Small closed meshes and skeletons with known geometry for the distance tests: tessellated
// boxes, a U-shaped prism, tori, spheres, and rigid motions that keep faces off the grid planes.

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "framework/geometry/mesh.hpp"
#include "framework/geometry/skeleton.hpp"

namespace skinlab::testing {

/// Accumulates vertices and triangles; vertices along shared patch borders are duplicated, which
/// changes nothing for voxelisation or distances.
class MeshBuilder {
 public:
  /// A grid of nu×nv quads (two triangles each) spanning corner + [0,1]·u + [0,1]·v.
  MeshBuilder& quad_grid(const Eigen::Vector3d& corner, const Eigen::Vector3d& u,
                         const Eigen::Vector3d& v, int nu, int nv) {
    const int base = static_cast<int>(vertices_.size());
    for (int j = 0; j <= nv; ++j)
      for (int i = 0; i <= nu; ++i) vertices_.push_back(corner + u * i / nu + v * j / nv);
    for (int j = 0; j < nv; ++j) {
      for (int i = 0; i < nu; ++i) {
        const int a = base + j * (nu + 1) + i, b = a + 1, c = a + nu + 1, d = c + 1;
        faces_.push_back({a, b, d});
        faces_.push_back({a, d, c});
      }
    }
    return *this;
  }

  /// Closed axis-aligned box [lo, hi], each face an n×n grid.
  MeshBuilder& box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int n) {
    const Eigen::Vector3d e = hi - lo;
    const Eigen::Vector3d x(e.x(), 0, 0), y(0, e.y(), 0), z(0, 0, e.z());
    quad_grid(lo, x, y, n, n).quad_grid(lo + z, x, y, n, n);
    quad_grid(lo, x, z, n, n).quad_grid(lo + y, x, z, n, n);
    quad_grid(lo, y, z, n, n).quad_grid(lo + x, y, z, n, n);
    return *this;
  }

  /// Closed prism over the simple polygon `outline` (counter-clockwise, xy plane) from z = 0 to
  /// z = depth; `caps` are rectangles [x0, y0, x1, y1] tiling the polygon. Side walls are
  /// subdivided every ~`step` along the outline and in two along z (so each wall has vertices at
  /// mid-depth).
  MeshBuilder& prism(const std::vector<Eigen::Vector2d>& outline,
                     const std::vector<Eigen::Vector4d>& caps, double depth, double step) {
    const Eigen::Vector3d z(0, 0, depth);
    for (std::size_t k = 0; k < outline.size(); ++k) {
      const Eigen::Vector2d a = outline[k], b = outline[(k + 1) % outline.size()];
      const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
      quad_grid(Eigen::Vector3d(a.x(), a.y(), 0), Eigen::Vector3d(b.x() - a.x(), b.y() - a.y(), 0),
                z, n, 2);
    }
    for (const auto& r : caps) {
      const Eigen::Vector3d corner(r[0], r[1], 0), u(r[2] - r[0], 0, 0), v(0, r[3] - r[1], 0);
      const int nu = std::max(1, static_cast<int>(std::ceil(u.norm() / step)));
      const int nv = std::max(1, static_cast<int>(std::ceil(v.norm() / step)));
      quad_grid(corner, u, v, nu, nv).quad_grid(corner + z, u, v, nu, nv);
    }
    return *this;
  }

  /// Torus around the z axis through `center`: ring radius R, tube radius r.
  MeshBuilder& torus(const Eigen::Vector3d& center, double R, double r, int nu, int nv) {
    const int base = static_cast<int>(vertices_.size());
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        const double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
        vertices_.push_back(center + Eigen::Vector3d((R + r * std::cos(v)) * std::cos(u),
                                                     (R + r * std::cos(v)) * std::sin(u),
                                                     r * std::sin(v)));
      }
    }
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        const int a = base + i * nv + j, b = base + ((i + 1) % nu) * nv + j;
        const int c = base + i * nv + (j + 1) % nv, d = base + ((i + 1) % nu) * nv + (j + 1) % nv;
        faces_.push_back({a, b, d});
        faces_.push_back({a, d, c});
      }
    }
    return *this;
  }

  /// UV sphere with poles.
  MeshBuilder& sphere(const Eigen::Vector3d& center, double r, int nu, int nv) {
    const int base = static_cast<int>(vertices_.size());
    vertices_.push_back(center + Eigen::Vector3d(0, 0, r));
    for (int j = 1; j < nv; ++j) {
      for (int i = 0; i < nu; ++i) {
        const double u = 2 * M_PI * i / nu, v = M_PI * j / nv;
        vertices_.push_back(center + r * Eigen::Vector3d(std::sin(v) * std::cos(u),
                                                         std::sin(v) * std::sin(u), std::cos(v)));
      }
    }
    const int south = static_cast<int>(vertices_.size());
    vertices_.push_back(center - Eigen::Vector3d(0, 0, r));
    auto ring = [&](int j, int i) { return base + 1 + (j - 1) * nu + (i % nu); };
    for (int i = 0; i < nu; ++i) {
      faces_.push_back({base, ring(1, i), ring(1, i + 1)});
      faces_.push_back({south, ring(nv - 1, i + 1), ring(nv - 1, i)});
      for (int j = 1; j + 1 < nv; ++j) {
        faces_.push_back({ring(j, i), ring(j + 1, i), ring(j + 1, i + 1)});
        faces_.push_back({ring(j, i), ring(j + 1, i + 1), ring(j, i + 1)});
      }
    }
    return *this;
  }

  geometry::Mesh build() const {
    geometry::Mesh m;
    m.V.resize(static_cast<Eigen::Index>(vertices_.size()), 3);
    for (std::size_t v = 0; v < vertices_.size(); ++v) m.V.row(v) = vertices_[v];
    m.F.resize(static_cast<Eigen::Index>(faces_.size()), 3);
    for (std::size_t f = 0; f < faces_.size(); ++f) {
      m.F.row(f) << faces_[f][0], faces_[f][1], faces_[f][2];
    }
    m.validate("test mesh");
    return m;
  }

 private:
  std::vector<Eigen::Vector3d> vertices_;
  std::vector<std::array<int, 3>> faces_;
};

/// A chain j0 -> j1 -> ... through `points` (one row each); one row gives a one-joint skeleton.
inline geometry::Skeleton chain(const Eigen::MatrixXd& points) {
  std::vector<std::string> names, parents;
  for (Eigen::Index j = 0; j < points.rows(); ++j) {
    names.push_back("j" + std::to_string(j));
    parents.push_back(j == 0 ? "" : "j" + std::to_string(j - 1));
  }
  return geometry::Skeleton::from_parent_names(names, points, parents, "test skeleton");
}

/// Applies the same rotation (about the origin) to mesh and skeleton, so that no face is parallel
/// to a grid plane and no vertex lies on one except by chance of measure zero.
inline void rotate(geometry::Mesh& mesh, geometry::Skeleton& skeleton, const Eigen::Matrix3d& R) {
  mesh.V = (mesh.V * R.transpose()).eval();
  skeleton.positions = (skeleton.positions * R.transpose()).eval();
}

inline Eigen::Matrix3d some_rotation(double a, double b, double c) {
  return (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(b, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(c, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

/// Index of the vertex of `mesh` closest to `p`.
inline int nearest_vertex(const geometry::Mesh& mesh, const Eigen::Vector3d& p) {
  Eigen::Index best = 0;
  (mesh.V.rowwise() - p.transpose()).rowwise().squaredNorm().minCoeff(&best);
  return static_cast<int>(best);
}

}  // namespace skinlab::testing

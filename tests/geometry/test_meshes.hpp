#pragma once
// Small meshes built in code for the geometry tests, and a connectivity check.

#include <Eigen/Core>
#include <cmath>
#include <queue>
#include <vector>

#include "framework/geometry/mesh.hpp"
#include "framework/geometry/one_ring.hpp"

namespace skinlab::testing {

/// Σ a·(b × c) / 6 over faces [first, first + count) of (V, F) (count < 0: to the last): the
/// volume they enclose, positive when they are wound counter-clockwise seen from outside.
inline double signed_volume(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                            Eigen::Index first = 0, Eigen::Index count = -1) {
  const Eigen::Index end = count < 0 ? F.rows() : first + count;
  double v = 0;
  for (Eigen::Index f = first; f < end; ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    v += a.dot(b.cross(c)) / 6;
  }
  return v;
}

/// Regular tetrahedron-like closed mesh: 4 vertices, 6 edges, 4 outward faces.
inline geometry::Mesh tetrahedron() {
  geometry::Mesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0,  //
      1, 0, 0,     //
      0, 1, 0,     //
      0, 0, 1;
  m.F.resize(4, 3);
  m.F << 0, 2, 1,  //
      0, 1, 3,     //
      0, 3, 2,     //
      1, 2, 3;
  return m;
}

/// Flat (nx+1)×(ny+1) grid in the plane z = 0 with spacing h; vertex (i, j) has index
/// j·(nx+1) + i; every cell is split along its (i, j)–(i+1, j+1) diagonal, so the triangles are
/// right isosceles. `jitter` moves interior vertices in x/y by a deterministic amount up to
/// jitter·h, which breaks distance ties.
inline geometry::Mesh grid(int nx, int ny, double h = 1.0, double jitter = 0.0) {
  geometry::Mesh m;
  m.V.resize((nx + 1) * (ny + 1), 3);
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      const int v = j * (nx + 1) + i;
      const bool interior = i > 0 && j > 0 && i < nx && j < ny;
      const double dx = interior ? jitter * std::sin(12.9898 * v + 1.0) : 0.0;
      const double dy = interior ? jitter * std::sin(78.233 * v + 2.0) : 0.0;
      m.V.row(v) << (i + dx) * h, (j + dy) * h, 0.0;
    }
  }
  m.F.resize(2 * nx * ny, 3);
  int f = 0;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
      m.F.row(f++) << a, b, d;
      m.F.row(f++) << a, d, c;
    }
  }
  return m;
}

/// Unit cube whose 6 sides are separate quads (4 own vertices each, 2 triangles): 24 vertices,
/// 12 faces, 8 distinct positions, the way exporters write per-face normals or UVs.
inline geometry::Mesh cube_as_separate_quads() {
  const int corners[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  geometry::Mesh m;
  m.V.resize(24, 3);
  m.F.resize(12, 3);
  for (int s = 0; s < 6; ++s) {
    for (int k = 0; k < 4; ++k) {
      const int c = corners[s][k];
      m.V.row(4 * s + k) << (c & 1), (c >> 1) & 1, (c >> 2) & 1;
    }
    m.F.row(2 * s) << 4 * s, 4 * s + 1, 4 * s + 2;
    m.F.row(2 * s + 1) << 4 * s, 4 * s + 2, 4 * s + 3;
  }
  return m;
}

/// Number of connected components of the vertices referenced by faces (edge graph).
inline int num_components(const geometry::Mesh& mesh) {
  const auto ring = geometry::one_ring(mesh);
  std::vector<int> seen(ring.neighbours.size(), 0);
  std::vector<int> used(ring.neighbours.size(), 0);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[mesh.F(f, k)] = 1;
  int components = 0;
  for (size_t s = 0; s < ring.neighbours.size(); ++s) {
    if (!used[s] || seen[s]) continue;
    ++components;
    std::queue<int> q;
    q.push(static_cast<int>(s));
    seen[s] = 1;
    while (!q.empty()) {
      const int u = q.front();
      q.pop();
      for (int w : ring.neighbours[u]) {
        if (!seen[w]) {
          seen[w] = 1;
          q.push(w);
        }
      }
    }
  }
  return components;
}

}  // namespace skinlab::testing

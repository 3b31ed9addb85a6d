#pragma once
/// \file
/// One-ring neighbourhoods: the mesh-topology half of HeterSkinNet's mesh EdgeConv
/// (Pan et al. 2021, Sec. 3.3, N_m(v_i) in Eq. 2; RigNet's `get_tpl_edges`).

#include <Eigen/Core>
#include <vector>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

struct OneRing {
  /// #V lists: neighbours[i] holds every vertex sharing a face edge with i, sorted ascending,
  /// without duplicates and without i itself (a face with a repeated index adds no self-loop).
  /// A vertex referenced by no face has an empty list.
  std::vector<std::vector<int>> neighbours;
  /// 2×E directed edges, both directions of every undirected edge (E = 2 #undirected edges):
  /// column e = (i, j) with row 0 the vertex i whose neighbourhood it is and row 1 its neighbour
  /// j, ordered by i then j. This is RigNet's `*_tpl_e.txt` layout after transposition; the
  /// graph is symmetric, so the message direction of a convolution does not matter here.
  Eigen::Matrix2Xi edges;
};

/// One-ring neighbours of every vertex of `mesh` (#V×3, #F×3). Non-manifold edges and disjoint
/// parts need no special care: adjacency is read face by face.
/// Throws GeometryError for an invalid mesh (Mesh::validate).
OneRing one_ring(const Mesh& mesh);

}  // namespace skinlab::geometry

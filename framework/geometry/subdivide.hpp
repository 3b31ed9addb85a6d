#pragma once
/// \file
/// Midpoint (1-to-4) subdivision of small meshes into HeterSkinNet's vertex range (Pan et al.
/// 2021, Sec. 4.1: "for models with less than 1K vertices, we subdivide their meshes so that
/// their vertex numbers range from 1K to 5K", so that every character has a similar weight in
/// training). Midpoint subdivision does not move the original vertices or change the shape,
/// so distances to bones and artist weights stay meaningful on the refined mesh.

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

struct SubdivideOptions {
  int min_vertices = 1000;  ///< subdivide while #V < min_vertices
  int max_vertices = 5000;  ///< never perform a step that would give more vertices than this
};

struct SubdividedMesh {
  Mesh mesh;  ///< #V_new×3, #F_new×3 (#F_new = 4^levels · #F)
  /// #V_new×#V_old interpolation matrix: per-vertex data interpolates as new = S · old. Row i <
  /// #V_old is the unit vector e_i (original vertices keep their index, so results on the
  /// subdivided mesh map back as its first #V_old rows); a later row holds the parent vertices
  /// of a midpoint with weights 1/2^k summing to 1.
  Eigen::SparseMatrix<double, Eigen::RowMajor> S;
  int levels = 0;  ///< number of 1-to-4 steps performed (0: the mesh was already large enough)
};

/// Repeats midpoint subdivision while #V < min_vertices, stopping before a step whose result
/// would exceed max_vertices. A step adds one vertex per undirected edge (shared edges are found
/// with an edge map, so each gets one midpoint and the mesh stays connected): #V' = #V + #E,
/// #F' = 4 #F; every triangle (a, b, c) with midpoints m_ab, m_bc, m_ca becomes (a, m_ab, m_ca),
/// (m_ab, b, m_bc), (m_ca, m_bc, c), (m_ab, m_bc, m_ca), which keeps the orientation. Midpoints
/// are numbered in order of first appearance over faces and their edges (ab, bc, ca), so the
/// output is deterministic. If one step jumps from below min_vertices to above max_vertices
/// (meshes with many open or disjoint triangles, #E ≫ #V), the mesh is returned below
/// min_vertices: a too-small mesh is usable, one beyond the range costs memory quadratically in
/// later all-pairs distances. An edge whose two indices are equal (degenerate input face) gets
/// no new vertex: its "midpoint" is the vertex itself.
///
/// Throws GeometryError for an invalid mesh (Mesh::validate) or options with
/// min_vertices > max_vertices.
SubdividedMesh subdivide(const Mesh& mesh, const SubdivideOptions& options = {});

}  // namespace skinlab::geometry

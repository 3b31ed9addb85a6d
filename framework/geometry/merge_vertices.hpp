#pragma once
/// \file
/// Merging of vertices that share a position: the first pre-processing step of HeterSkinNet
/// (Pan et al. 2021, Sec. 4.1). Characters built from several parts carry duplicate vertices at
/// the seams; they have the same skin weights but no shared edges, so without merging the mesh
/// graph falls apart there and the two copies can be predicted differently. The paper merges them
/// "when building the mesh graph and assign[s] the same prediction results to the vertices in that
/// position": `merged.old_to_new` is the map that makes both directions possible (see
/// map_vertex_data.hpp).

#include <Eigen/Core>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

struct MergeOptions {
  /// Vertices closer than this (Euclidean, metres) to an earlier kept vertex are merged into it.
  /// 0 (the default) merges only bit-identical positions (−0 and +0 count as equal), which is
  /// what the paper does. Must be finite and ≥ 0.
  double tolerance = 0.0;
};

struct MergedMesh {
  Mesh mesh;  ///< #V_new×3 positions, #F_new×3 faces (faces that became degenerate are dropped)
  /// #V_old: new vertex index of every input vertex. New vertex n is the n-th distinct position
  /// met in input order, so the result depends only on the input order, never on hashing.
  Eigen::VectorXi old_to_new;
  /// #F_new: index into the input F of every kept face (input order is preserved).
  Eigen::VectorXi kept_faces;
};

/// Merges vertices at the same position (within `options.tolerance`) and drops faces that end up
/// with two equal vertex indices. A merged vertex keeps the position of its first occurrence (the
/// representative), and with a tolerance a vertex joins the first representative within reach, so
/// the result never depends on hash order. Vertices referenced by no face are kept.
///
/// Faces that were already degenerate in the input (repeated index) are dropped as well;
/// zero-area faces with three distinct indices are kept (game meshes have them; the Laplacian
/// copes, see laplacian.hpp).
///
/// Throws GeometryError for an invalid mesh (Mesh::validate), a negative or non-finite
/// tolerance, and when every face becomes degenerate.
MergedMesh merge_vertices(const Mesh& mesh, const MergeOptions& options = {});

}  // namespace skinlab::geometry

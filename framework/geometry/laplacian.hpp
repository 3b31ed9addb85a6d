#pragma once
/// \file
/// Mesh Laplacians for the smoothing term of HeterSkinNet (Pan et al. 2021, Sec. 3.4, Eq. 6):
/// L_S = Σ_j w_jᵀ L w_j over the #V weight columns w_j of the bones.
///
/// Convention: positive semi-definite, L = D − A with A_ij ≥ 0 the weight of edge ij (for
/// `kCotangent`, possibly negative, see below) and D_ii = Σ_j A_ij, so L is symmetric, every row
/// sums to zero and wᵀ L w = Σ_{edges ij} A_ij (w_i − w_j)² ≥ 0 penalises differences across
/// edges.
///
/// Which one to train with: **kUniform**. HeterSkinNet does not say which Laplacian it uses.
/// The characters of ModelsResource-RigNetv1 are game meshes: mostly non-manifold, with disjoint
/// parts and degenerate or needle triangles (Sec. 4.1). The uniform Laplacian depends only on
/// connectivity, so every edge weighs 1 whatever the triangle quality and the loss has the
/// same scale on every character. Cotangent weights grow like 1/angle on needle triangles, so a
/// handful of bad triangles would dominate Eq. 6, and they turn negative on obtuse triangles.
/// The cotangent Laplacian is the better discretisation of the smooth Dirichlet energy on
/// well-shaped meshes (it does not depend on tessellation density); use it for clean, remeshed
/// data or for comparison.

#include <Eigen/Sparse>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

enum class LaplacianKind {
  kUniform,    ///< graph Laplacian: A_ij = 1 for every undirected edge
  kCotangent,  ///< A_ij = ½ Σ cot of the angles opposite edge ij, over all incident triangles
};

struct LaplacianOptions {
  LaplacianKind kind = LaplacianKind::kUniform;
  /// kCotangent only: set negative edge weights (edges opposite obtuse angles) to zero. Without
  /// it L is still PSD (it is a sum of per-triangle P1 stiffness matrices, each PSD) but is not
  /// an M-matrix, so smoothing can overshoot; with it L is a graph Laplacian with weights ≥ 0.
  bool clamp_negative = false;
  /// kCotangent only: a triangle whose doubled area |e1 × e2| is at most this times its longest
  /// squared edge is degenerate (a cotangent above about 1/this) and contributes nothing, so
  /// zero-area and needle triangles cannot produce Inf or NaN.
  double degenerate_ratio = 1e-10;
};

/// #V×#V Laplacian of `mesh` (#V×3 metres, #F×3) in the PSD convention of the file comment.
/// Symmetric by construction (A_ij and A_ji are the same double) and rows sum to zero up to
/// rounding (D is the sum of the row's off-diagonal entries). Edges with repeated indices are
/// ignored; non-manifold edges simply collect the terms of all their triangles; isolated
/// vertices get an empty row. Units: kUniform is dimensionless, kCotangent too (cotangents).
///
/// Throws GeometryError for an invalid mesh (Mesh::validate) or a degenerate_ratio that is not
/// finite and ≥ 0.
Eigen::SparseMatrix<double> laplacian(const Mesh& mesh, const LaplacianOptions& options = {});

}  // namespace skinlab::geometry

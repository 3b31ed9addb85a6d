#pragma once
/// \file
/// Skin weights and the rigged character that carries them.
///
/// Weights are stored per joint (#V×#J): every source format (RigNet's rig text, FBX/glTF
/// skins, 0 A.D. PMD) stores them so, and a bone's weight is its start joint's weight (RigNet).
/// Bone-level targets for a network are derived from these with a distance: among the bones
/// starting at joint j, the weight goes to the one nearest the vertex (RigNet's gen_dataset.py).

#include <Eigen/Sparse>
#include <string>

#include "framework/geometry/mesh.hpp"
#include "framework/geometry/skeleton.hpp"

namespace skinlab::geometry {

using SparseWeights = Eigen::SparseMatrix<double, Eigen::RowMajor>;

struct WeightCheck {
  double tolerance = 1e-3;   ///< |row sum − 1| allowed
  bool renormalise = false;  ///< divide rows by their sum instead of rejecting them
  /// Keep a vertex with no weight as an empty row instead of rejecting it: only for scoring
  /// another method's output that leaves vertices unweighted (Blender's automatic weights do).
  bool allow_unweighted = false;
};

/// Checks (and with `renormalise`, fixes) per-vertex weights W (#V×#J). Throws GeometryError,
/// prefixed by `source`, naming the vertex and joint for: a shape other than
/// num_vertices×num_joints, non-finite or negative weights, a vertex with no weight (unless
/// `allow_unweighted`), and (unless
/// renormalising) a row whose sum differs from 1 by more than the tolerance. Explicit zeros are
/// pruned.
void check_weights(SparseWeights& W, int num_vertices, const Skeleton& skeleton,
                   const std::string& source, const WeightCheck& options = {});

/// A rigged character: mesh, skeleton and (for training data) artist weights.
struct Character {
  std::string name;
  Mesh mesh;
  Skeleton skeleton;
  SparseWeights weights;  ///< #V×#J; empty (0×0) when the character carries none

  bool has_weights() const { return weights.rows() > 0; }
  /// Validates mesh, skeleton and (if present) weights, with `name` as the source.
  void validate(const WeightCheck& options = {});
};

}  // namespace skinlab::geometry

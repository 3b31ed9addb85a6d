#pragma once
/// \file
/// What a skeletal game format decodes to, and its conversion to a Character and Animations.
/// Shared by the binary readers (cube2's IQM, Nexuiz's ZYM), whose files store joints with
/// parent-relative transforms.
///
/// Game rigs carry control joints that skin nothing: IK targets, wing and eye controls, weapon
/// attachment points, often as extra roots (Frankie has 2 roots, Nexuiz players 2–7). A
/// Skeleton has exactly one root, so `to_source_rig` removes every root whose whole subtree has
/// no weight; control joints inside the skinned tree are kept (they are part of the hierarchy).
/// If more than one root still carries weights the model cannot be one tree and is rejected.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "framework/data/source.hpp"
#include "framework/geometry/skin_weights.hpp"

namespace skinlab::datasets {

using Transforms = std::vector<Eigen::Isometry3d>;

/// A skinned model as the file gives it, every joint included.
struct RiggedModel {
  std::string name;                      ///< character name
  std::vector<std::string> joint_names;  ///< #J
  std::vector<int> parents;              ///< #J parent index, -1 for a root; parent < child
  Transforms bind;                       ///< #J global bind-pose transforms (file frame, units)
  Eigen::MatrixXd V;                     ///< #V×3 bind-pose positions (file frame, units)
  Eigen::MatrixXi F;                     ///< #F×3 triangles
  geometry::SparseWeights W;             ///< #V×#J weights, rows sum to 1
  /// #J flags (or empty): joints whose transforms are degenerate in some pose (e.g. all-zero
  /// matrices of unused helper bones); they are pruned with their subtrees, which must carry
  /// no weight.
  std::vector<bool> unusable;
};

/// A character with the map back to the file's joints, for converting animations.
struct SourceRig {
  geometry::Character character;  ///< validated; skeleton positions = bind translations
  std::vector<int> kept;          ///< kept[k]: file joint index of character joint k
  Transforms bind;                ///< bind transforms of the kept joints
};

/// Composes parent-relative transforms into global ones: G_j = G_parent(j) · L_j. Requires every
/// parent index to precede its child (both formats require this); throws GeometryError naming
/// `source` and the joint otherwise.
Transforms compose_global(const Transforms& local, const std::vector<int>& parents,
                          const std::vector<std::string>& names, const std::string& source);

/// Prunes unweighted root subtrees (see the file comment) and the subtrees of `unusable` joints,
/// builds and validates the Character. Throws GeometryError naming the model for several weighted
/// roots, a weighted unusable subtree, or any validation error.
SourceRig to_source_rig(const RiggedModel& model);

/// An Animation of `rig` from per-frame global transforms of all file joints
/// (frames[f] has #J entries, in the file's joint order).
Animation make_animation(const std::string& name, double fps,
                         const std::vector<Transforms>& global_frames, const SourceRig& rig);

/// Checks that `m` is a rotation (orthonormal, det +1, to `tolerance`) with finite entries and
/// returns it as an isometry; throws GeometryError "<what>: ..." otherwise.
Eigen::Isometry3d to_isometry(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation,
                              const std::string& what, double tolerance = 1e-3);

}  // namespace skinlab::datasets

#pragma once
/// \file
/// Skeleton: named joints in a tree, and the bones HeterSkinNet and RigNet build on it.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

/// A bone runs from joint `start` (the parent) to joint `end` (the child). A helper bone is the
/// bone added at every leaf joint "for skinning at the end of limbs" (HeterSkinNet Sec. 3.2;
/// RigNet's virtual leaf bones): `start == end`. In the paper it has zero length; where
/// Skeleton::leaf_tips is set it runs from the leaf joint to the leaf's tip
/// (distances/leaf_bones.hpp). A root with one child ends a chain as a leaf does; where its row of
/// `leaf_tips` is set apart from the root (leaf_bones' `roots`), the root has a helper bone too,
/// from the root to that tip (has_root_bone).
struct Bone {
  int start = -1;
  int end = -1;
  bool helper = false;
};

struct Skeleton {
  std::vector<std::string> names;  ///< #J unique joint names
  Eigen::MatrixXd positions;       ///< #J×3 joint positions in the mesh's frame
  std::vector<int> parents;        ///< #J parent joint index; -1 for the root
  /// #J×3 or empty. Empty: every helper bone has zero length (the paper). Set: the helper bone of
  /// leaf joint j ends at row j (distances/leaf_bones.hpp); rows of joints with children are the
  /// joint's own position, except the root's where it has a helper bone (has_root_bone).
  Eigen::MatrixXd leaf_tips;

  int num_joints() const { return static_cast<int>(names.size()); }
  /// Index of joint `name`, or -1.
  int find(const std::string& name) const;
  /// The root joint. Requires a valid skeleton.
  int root() const;
  /// children()[j]: the joints whose parent is j, in index order.
  std::vector<std::vector<int>> children() const;

  /// Bones in RigNet's order (`get_bones` in its common_ops.py): breadth-first from the root;
  /// for each parent, one bone per child in index order, each followed by the helper bone of
  /// that child if it is a leaf. A one-joint skeleton has a single helper bone. With a root
  /// helper bone (has_root_bone, not in RigNet) that bone comes first.
  std::vector<Bone> bones() const;

  /// True when the root has children and its row of `leaf_tips` lies apart from it (farther
  /// than 1e-5 × the joints' bounding-box diagonal, so that rounding of a row that equals the
  /// root never counts): the root then starts a helper bone to that tip, as a leaf does. Only
  /// leaf_bones' `roots` option places such a tip (distances/leaf_bones.hpp).
  bool has_root_bone() const;

  /// #B×6 rows [start xyz, end xyz] of `bones()`, the bone attribute of HeterSkinNet Sec. 3.2;
  /// a helper bone ends at its leaf tip when `leaf_tips` is set (bone_end).
  Eigen::MatrixXd bone_segments() const;
  /// Where bone `b` ends: its end joint, or for a helper bone the leaf's tip when `leaf_tips` is
  /// set (the joint itself otherwise).
  Eigen::Vector3d bone_end(const Bone& b) const;

  /// Throws GeometryError, prefixed by `source`, for: no joints, sizes that disagree, empty or
  /// duplicate joint names, non-finite positions, parent indices out of range, no root, several
  /// roots, cycles (naming the joints involved), and leaf tips that are neither empty nor #J×3
  /// finite values.
  void validate(const std::string& source) const;

  /// Builds a skeleton from joint names, positions and parent names ("" for the root) and
  /// validates it. An unknown parent name is an error naming the joint and the parent.
  static Skeleton from_parent_names(std::vector<std::string> names, Eigen::MatrixXd positions,
                                    const std::vector<std::string>& parent_names,
                                    const std::string& source);
};

}  // namespace skinlab::geometry

#pragma once
/// \file
/// Skeleton: named joints in a tree, and the bones HeterSkinNet and RigNet build on it.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

/// A bone runs from joint `start` (the parent) to joint `end` (the child). A helper bone is the
/// zero-length bone added at every leaf joint "for skinning at the end of limbs" (HeterSkinNet
/// Sec. 3.2; RigNet's virtual leaf bones): `start == end`.
struct Bone {
  int start = -1;
  int end = -1;
  bool helper = false;
};

struct Skeleton {
  std::vector<std::string> names;  ///< #J unique joint names
  Eigen::MatrixXd positions;       ///< #J×3 joint positions in the mesh's frame
  std::vector<int> parents;        ///< #J parent joint index; -1 for the root

  int num_joints() const { return static_cast<int>(names.size()); }
  /// Index of joint `name`, or -1.
  int find(const std::string& name) const;
  /// The root joint. Requires a valid skeleton.
  int root() const;
  /// children()[j]: the joints whose parent is j, in index order.
  std::vector<std::vector<int>> children() const;

  /// Bones in RigNet's order (`get_bones` in its common_ops.py): breadth-first from the root;
  /// for each parent, one bone per child in index order, each followed by the helper bone of
  /// that child if it is a leaf. A one-joint skeleton has a single helper bone.
  std::vector<Bone> bones() const;

  /// #B×6 rows [start xyz, end xyz] of `bones()`, the bone attribute of HeterSkinNet Sec. 3.2.
  Eigen::MatrixXd bone_segments() const;

  /// Throws GeometryError, prefixed by `source`, for: no joints, sizes that disagree, empty or
  /// duplicate joint names, non-finite positions, parent indices out of range, no root, several
  /// roots, and cycles (naming the joints involved).
  void validate(const std::string& source) const;

  /// Builds a skeleton from joint names, positions and parent names ("" for the root) and
  /// validates it. An unknown parent name is an error naming the joint and the parent.
  static Skeleton from_parent_names(std::vector<std::string> names, Eigen::MatrixXd positions,
                                    const std::vector<std::string>& parent_names,
                                    const std::string& source);
};

}  // namespace skinlab::geometry

#include "framework/data/source.hpp"

namespace skinlab::datasets {

namespace {

/// M·T·M for the mirror M = diag(1, 1, −1): a rigid transform of the mirrored frame.
Eigen::Isometry3d mirrored_z(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d M = Eigen::Vector3d(1, 1, -1).asDiagonal();
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = M * T.linear() * M;
  out.translation() = M * T.translation();
  return out;
}

void mirror_all(std::vector<Eigen::Isometry3d>& transforms) {
  for (auto& T : transforms) T = mirrored_z(T);
}

}  // namespace

void make_right_handed(SourceCharacter& source) {
  if (!source.left_handed) return;
  geometry::Character& c = source.character;
  c.mesh.V.col(2) *= -1.0;
  c.skeleton.positions.col(2) *= -1.0;
  if (c.skeleton.leaf_tips.rows() > 0) c.skeleton.leaf_tips.col(2) *= -1.0;
  mirror_all(source.bind);
  for (auto& clip : source.animations) {
    mirror_all(clip.bind);
    for (auto& frame : clip.frames) mirror_all(frame);
  }
  source.left_handed = false;
}

}  // namespace skinlab::datasets

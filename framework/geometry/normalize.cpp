#include "framework/geometry/normalize.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace skinlab::geometry {

Eigen::MatrixXd Similarity::apply(const Eigen::MatrixXd& P) const {
  return ((scale * P * rotation.transpose()).rowwise() + translation.transpose()).eval();
}

Similarity Similarity::inverse() const {
  Similarity out;
  out.scale = 1.0 / scale;
  out.rotation = rotation.transpose();
  out.translation = -out.scale * (out.rotation * translation);
  return out;
}

Similarity Similarity::after(const Similarity& first) const {
  Similarity out;
  out.scale = scale * first.scale;
  out.rotation = rotation * first.rotation;
  out.translation = scale * (rotation * first.translation) + translation;
  return out;
}

Eigen::Matrix4d Similarity::matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = scale * rotation;
  m.topRightCorner<3, 1>() = translation;
  return m;
}

Similarity normalize(Character& character, const NormalizeOptions& options) {
  const std::string at = character.name + ": ";
  const double n = options.source_up.norm();
  if (!std::isfinite(n) || n == 0) {
    throw GeometryError(at + "normalisation needs a non-zero, finite source up axis");
  }
  const Eigen::Vector3d up = options.source_up / n;
  Similarity rotate;
  if (up.dot(Eigen::Vector3d::UnitY()) < -1 + 1e-12) {
    // FromTwoVectors picks an arbitrary axis for opposite vectors; fix it to X for
    // reproducibility.
    rotate.rotation = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  } else {
    rotate.rotation =
        Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitY()).toRotationMatrix();
  }
  if (character.mesh.V.rows() == 0) throw GeometryError(at + "cannot normalise an empty mesh");
  const Eigen::MatrixXd R = rotate.apply(character.mesh.V);
  const Eigen::RowVector3d lo = R.colwise().minCoeff();
  const Eigen::RowVector3d hi = R.colwise().maxCoeff();
  const double extent = hi.y() - lo.y();
  if (!(extent > 0)) {
    throw GeometryError(at + "cannot normalise: the mesh has zero height along the up axis");
  }
  Similarity place;
  place.scale = options.height / extent;
  place.translation = -place.scale * Eigen::Vector3d(0.5 * (lo.x() + hi.x()), lo.y(),
                                                     0.5 * (lo.z() + hi.z()));
  const Similarity total = place.after(rotate);
  character.mesh.V = total.apply(character.mesh.V);
  if (character.skeleton.positions.rows() > 0) {
    character.skeleton.positions = total.apply(character.skeleton.positions);
  }
  return total;
}

}  // namespace skinlab::geometry

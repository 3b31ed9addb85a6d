#include "framework/distances/euclidean.hpp"

#include <algorithm>

#include "framework/core/registry.hpp"

namespace skinlab::distances {

double point_segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  // Projection parameter clamped to the segment; a zero-length (helper) bone is its start point.
  const double t = length2 > 0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

Euclidean::Options Euclidean::Options::from(const config::Node& node) {
  config::Fields f(node, "distance 'euclidean'");
  f.finish();
  return {};
}

Eigen::MatrixXd Euclidean::compute(const geometry::Mesh& mesh,
                                   const geometry::Skeleton& skeleton) const {
  mesh.validate("euclidean distance");
  skeleton.validate("euclidean distance");
  const Eigen::MatrixXd segments = skeleton.bone_segments();
  Eigen::MatrixXd D(mesh.num_vertices(), segments.rows());
  for (Eigen::Index b = 0; b < segments.rows(); ++b) {
    const Eigen::Vector3d a = segments.row(b).head<3>(), e = segments.row(b).tail<3>();
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      D(v, b) = point_segment_distance(mesh.V.row(v).transpose(), a, e);
    }
  }
  return D;
}

}  // namespace skinlab::distances

SKINLAB_REGISTER(distance, euclidean, skinlab::distances::Euclidean);

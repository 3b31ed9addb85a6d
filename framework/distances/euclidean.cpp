#include "framework/distances/euclidean.hpp"

#include "framework/core/registry.hpp"
#include "framework/geometry/closest_point_on_segment.hpp"

namespace skinlab::distances {

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
      D(v, b) = geometry::point_segment_distance(mesh.V.row(v).transpose(), a, e);
    }
  }
  return D;
}

}  // namespace skinlab::distances

SKINLAB_REGISTER(distance, euclidean, skinlab::distances::Euclidean);

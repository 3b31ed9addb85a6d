#include "framework/geometry/vertex_normals.hpp"

#include <Eigen/Geometry>

namespace skinlab::geometry {

Eigen::MatrixXd vertex_normals(const Mesh& mesh) {
  Eigen::MatrixXd n = Eigen::MatrixXd::Zero(mesh.V.rows(), 3);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                          c = mesh.V.row(mesh.F(f, 2));
    const Eigen::RowVector3d area_normal = (b - a).cross(c - a).transpose();
    for (int k = 0; k < 3; ++k) n.row(mesh.F(f, k)) += area_normal;
  }
  for (Eigen::Index v = 0; v < n.rows(); ++v) {
    const double length = n.row(v).norm();
    n.row(v) = length > 1e-12 ? Eigen::RowVector3d(n.row(v) / length) : Eigen::RowVector3d::Zero();
  }
  return n;
}

}  // namespace skinlab::geometry

#include "framework/geometry/mesh.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace skinlab::geometry {

void Mesh::validate(const std::string& source) const {
  const std::string at = source + ": ";
  if (V.rows() == 0) throw GeometryError(at + "mesh has no vertices");
  if (V.cols() != 3) throw GeometryError(at + "vertex matrix must be #V×3, got " + std::to_string(V.cols()) + " columns");
  if (F.rows() == 0) throw GeometryError(at + "mesh has no faces");
  if (F.cols() != 3) throw GeometryError(at + "face matrix must be #F×3 (triangles), got " + std::to_string(F.cols()) + " columns");
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    if (!V.row(v).allFinite()) {
      throw GeometryError(at + "vertex " + std::to_string(v) + " has a non-finite coordinate (" +
                          std::to_string(V(v, 0)) + ", " + std::to_string(V(v, 1)) + ", " +
                          std::to_string(V(v, 2)) + ")");
    }
  }
  bool any_area = false;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (F(f, k) < 0 || F(f, k) >= V.rows()) {
        throw GeometryError(at + "face " + std::to_string(f) + " refers to vertex " +
                            std::to_string(F(f, k)) + ", but the mesh has " +
                            std::to_string(V.rows()) + " vertices");
      }
    }
    if (!any_area) {
      const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
      any_area = (b - a).cross(c - a).norm() > 0;
    }
  }
  if (!any_area) throw GeometryError(at + "every face of the mesh is degenerate (zero area)");
}

}  // namespace skinlab::geometry

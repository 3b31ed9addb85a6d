#include "framework/geometry/closest_point_on_segment.hpp"

#include <algorithm>

namespace skinlab::geometry {

Eigen::Vector3d closest_point_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                         const Eigen::Vector3d& b, double point_below_squared) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  if (length2 <= point_below_squared || length2 == 0) return a;
  return a + std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) * ab;
}

double point_segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b) {
  return (p - closest_point_on_segment(p, a, b)).norm();
}

}  // namespace skinlab::geometry

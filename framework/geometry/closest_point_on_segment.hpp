#pragma once
/// \file
/// Point–segment queries, shared by every distance that measures to a bone.

#include <Eigen/Core>

namespace skinlab::geometry {

/// Closest point of the closed segment [a, b] to p. A segment whose squared length is at most
/// `point_below_squared` is the point a: 0 treats only exact helper bones (a == b) so; RigNet's
/// volumetric geodesic uses 1e-8 (its `compute_volumetric_geodesic.py`).
Eigen::Vector3d closest_point_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                         const Eigen::Vector3d& b,
                                         double point_below_squared = 0.0);

/// |p − closest_point_on_segment(p, a, b)|: the distance to a helper bone is the distance to its
/// joint. Units of the inputs.
double point_segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b);

}  // namespace skinlab::geometry

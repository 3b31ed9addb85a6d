#pragma once
// A synthetic character for benchmarks at the dataset's sizes: a closed vertical body tube with
// a spine chain, and closed horizontal arm tubes radiating from the body's middle (intersecting
// it, as game meshes' separate parts do), each with a joint chain. Bones (Skeleton::bones(),
// with leaf helpers): spine_joints + arms · (arm_at.size() + 1).

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::bench {

struct BodyShape {
  int sides = 12;   ///< vertices per tube ring
  int rings = 12;   ///< rings per tube: (arms + 1) · (sides · rings + 2) vertices in all
  int arms = 6;
  int spine_joints = 3;              ///< evenly from y = 0.1 to 0.9; arms hang on the middle one
  std::vector<double> arm_at = {0.1, 0.2, 0.3, 0.42};  ///< arm joints, distance from the axis
};

inline void add_tube(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r, int sides,
                     int rings, std::vector<Eigen::Vector3d>& V, std::vector<Eigen::Vector3i>& F) {
  const Eigen::Vector3d axis = (b - a).normalized();
  Eigen::Vector3d u = std::abs(axis.x()) > 0.9 ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d(1, 0, 0);
  u = (u - u.dot(axis) * axis).normalized();
  const Eigen::Vector3d v = axis.cross(u);
  const int base = static_cast<int>(V.size());
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < sides; ++j) {
      const double t = 2 * M_PI * j / sides;
      V.push_back(a + (b - a) * i / (rings - 1) + r * (std::cos(t) * u + std::sin(t) * v));
    }
  }
  const auto id = [&](int i, int j) { return base + i * sides + j % sides; };
  for (int i = 0; i + 1 < rings; ++i) {
    for (int j = 0; j < sides; ++j) {
      F.emplace_back(id(i, j), id(i, j + 1), id(i + 1, j + 1));
      F.emplace_back(id(i, j), id(i + 1, j + 1), id(i + 1, j));
    }
  }
  const int ca = static_cast<int>(V.size());
  V.push_back(a);
  V.push_back(b);
  for (int j = 0; j < sides; ++j) {
    F.emplace_back(ca, id(0, j + 1), id(0, j));
    F.emplace_back(ca + 1, id(rings - 1, j), id(rings - 1, j + 1));
  }
}

/// The body of `shape`, named `name`, without weights.
inline geometry::Character make_body(const BodyShape& shape, const std::string& name = "body") {
  std::vector<Eigen::Vector3d> V;
  std::vector<Eigen::Vector3i> F;
  add_tube({0, 0.05, 0}, {0, 0.95, 0}, 0.08, shape.sides, shape.rings, V, F);
  std::vector<std::string> names, parents;
  std::vector<Eigen::Vector3d> joints;
  for (int s = 0; s < shape.spine_joints; ++s) {
    names.push_back("spine" + std::to_string(s));
    parents.push_back(s == 0 ? "" : names[names.size() - 2]);
    const double t = shape.spine_joints == 1 ? 0.5 : static_cast<double>(s) / (shape.spine_joints - 1);
    joints.emplace_back(0, 0.1 + 0.8 * t, 0);
  }
  const std::string hanger = names[static_cast<std::size_t>(shape.spine_joints / 2)];
  for (int k = 0; k < shape.arms; ++k) {
    const double phi = 2 * M_PI * (k + 0.25) / shape.arms;
    const Eigen::Vector3d dir(std::cos(phi), 0, std::sin(phi)), centre(0, 0.5, 0);
    add_tube(centre, centre + 0.45 * dir, 0.04, shape.sides, shape.rings, V, F);
    for (std::size_t j = 0; j < shape.arm_at.size(); ++j) {
      names.push_back("arm" + std::to_string(k) + "_" + std::to_string(j));
      parents.push_back(j == 0 ? hanger : names[names.size() - 2]);
      joints.push_back(centre + shape.arm_at[j] * dir);
    }
  }
  geometry::Character c;
  c.name = name;
  c.mesh.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (std::size_t i = 0; i < V.size(); ++i) c.mesh.V.row(static_cast<Eigen::Index>(i)) = V[i];
  c.mesh.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t i = 0; i < F.size(); ++i) c.mesh.F.row(static_cast<Eigen::Index>(i)) = F[i];
  Eigen::MatrixXd J(static_cast<Eigen::Index>(joints.size()), 3);
  for (std::size_t i = 0; i < joints.size(); ++i) J.row(static_cast<Eigen::Index>(i)) = joints[i];
  c.skeleton = geometry::Skeleton::from_parent_names(names, J, parents, name);
  return c;
}

}  // namespace skinlab::bench

#pragma once
/// \file
/// Interface of the `distance` registry: vertex–bone distances D (#V×#B) in the units of the
/// mesh (metres after normalisation), bones in `Skeleton::bones()` order. HeterSkinNet uses them
/// to pick each vertex's top-K candidate bones and as the vertex attribute 1/D (Sec. 3.2).

#include <Eigen/Core>

#include "framework/geometry/mesh.hpp"
#include "framework/geometry/skeleton.hpp"

namespace skinlab::distances {

class Distance {
 public:
  virtual ~Distance() = default;
  /// D(v, b): distance from vertex v to bone b, finite and ≥ 0 for every entry. Throws
  /// GeometryError if some vertex cannot be given a distance.
  virtual Eigen::MatrixXd compute(const geometry::Mesh& mesh,
                                  const geometry::Skeleton& skeleton) const = 0;
};

}  // namespace skinlab::distances

#pragma once
/// \file
/// `euclidean`: the straight-line vertex–bone distance that NeuroSkinning (Liu et al. 2019) uses
/// to pick candidate bones, and the baseline HollowDist is compared with (HeterSkinNet Sec. 3.1,
/// Table 3 "Euclidean"). It ignores the mesh, so its paths may cross the surface.

#include <Eigen/Core>

#include "framework/core/config.hpp"
#include "framework/distances/distance.hpp"

namespace skinlab::distances {

class Euclidean final : public Distance {
 public:
  /// No options; an unknown field is an error.
  struct Options {
    static Options from(const config::Node& node);
  };
  explicit Euclidean(Options /*options*/ = {}) {}

  /// #V×#B: D(v, b) = distance from vertex v to the segment of bone b (`Skeleton::bones()`
  /// order; a point for helper bones), in mesh units. Validates mesh and skeleton first.
  Eigen::MatrixXd compute(const geometry::Mesh& mesh,
                          const geometry::Skeleton& skeleton) const override;
};

}  // namespace skinlab::distances

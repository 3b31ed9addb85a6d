#include "framework/geometry/skin_weights.hpp"

#include <cmath>
#include <vector>

namespace skinlab::geometry {

void check_weights(SparseWeights& W, int num_vertices, const Skeleton& skeleton,
                   const std::string& source, const WeightCheck& options) {
  const std::string at = source + ": ";
  if (W.rows() != num_vertices || W.cols() != skeleton.num_joints()) {
    throw GeometryError(at + "weights are " + std::to_string(W.rows()) + "×" +
                        std::to_string(W.cols()) + ", expected #V×#J = " +
                        std::to_string(num_vertices) + "×" +
                        std::to_string(skeleton.num_joints()));
  }
  W.prune(0.0);
  W.makeCompressed();
  for (Eigen::Index v = 0; v < W.outerSize(); ++v) {
    double sum = 0;
    for (SparseWeights::InnerIterator it(W, v); it; ++it) {
      const std::string where = "vertex " + std::to_string(v) + ", joint '" +
                                skeleton.names[it.col()] + "'";
      if (!std::isfinite(it.value())) throw GeometryError(at + where + ": weight is not finite");
      if (it.value() < 0) {
        throw GeometryError(at + where + ": negative weight " + std::to_string(it.value()));
      }
      sum += it.value();
    }
    if (sum <= 0) {
      if (options.allow_unweighted) continue;
      throw GeometryError(at + "vertex " + std::to_string(v) + " has no weight");
    }
    if (std::abs(sum - 1.0) > options.tolerance) {
      if (!options.renormalise) {
        throw GeometryError(at + "vertex " + std::to_string(v) + ": weights sum to " +
                            std::to_string(sum) + ", not 1 (tolerance " +
                            std::to_string(options.tolerance) + "; renormalising is an option)");
      }
    }
    if (options.renormalise) {
      for (SparseWeights::InnerIterator it(W, v); it; ++it) it.valueRef() /= sum;
    }
  }
}

void Character::validate(const WeightCheck& options) {
  mesh.validate(name);
  skeleton.validate(name);
  if (has_weights()) check_weights(weights, mesh.num_vertices(), skeleton, name, options);
}

}  // namespace skinlab::geometry

#include "framework/binders/binder.hpp"

#include <cmath>

#include <fmt/format.h>

#include "framework/core/error.hpp"

namespace skinlab::binders {

Eigen::MatrixXd bind_checked(const Binder& binder, const geometry::Mesh& mesh,
                             const geometry::Skeleton& skeleton, const std::string& what) {
  Eigen::MatrixXd W = binder.bind(mesh, skeleton);
  const Eigen::Index num_vertices = mesh.V.rows();
  const auto num_bones = static_cast<Eigen::Index>(skeleton.bones().size());
  if (W.rows() != num_vertices || W.cols() != num_bones) {
    throw Error(fmt::format("{} returned {}×{} weights, expected {}×{}", what, W.rows(), W.cols(),
                            num_vertices, num_bones));
  }
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    const double sum = W.row(v).sum();
    if (!(W.row(v).minCoeff() >= 0) || !(std::abs(sum - 1.0) < 1e-4)) {
      throw Error(fmt::format("{}: vertex {} has weights summing to {} (min {})", what, v, sum,
                              W.row(v).minCoeff()));
    }
  }
  return W;
}

std::string reference_row_prior(const config::Node& node) {
  const std::string type = node.required_type("binder");
  config::Fields f(node, "binder " + type);
  std::string prior;
  if (type == kPriorOnCandidates) f.required("prior", prior);
  f.finish();
  return prior;
}

}  // namespace skinlab::binders

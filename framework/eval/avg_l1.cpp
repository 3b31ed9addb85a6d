#include "framework/eval/avg_l1.hpp"

#include "framework/core/registry.hpp"
#include "framework/eval/value_display.hpp"
#include "framework/eval/weights.hpp"

namespace skinlab::eval {

AvgL1::Options AvgL1::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "metric 'avg_l1'");
  f.optional("prune", o.prune).check(o.prune >= 0 && o.prune <= 1, "prune", "must be in [0, 1]");
  f.finish();
  return o;
}

Eigen::VectorXd AvgL1::vertex_errors(const MetricInputs& in) const {
  auto [P, G] = read_weights(in, "avg_l1");
  prune_rows(P, options_.prune);
  return (P - G).cwiseAbs().rowwise().sum();
}

std::map<std::string, double> AvgL1::operator()(const MetricInputs& in) const {
  const Eigen::VectorXd e = vertex_errors(in);
  return {{"avg_l1", e.size() > 0 ? e.mean() : 0.0}};
}

}  // namespace skinlab::eval

SKINLAB_DECLARE_VALUE({"avg_l1", "L1-norm", "", false, false, 4});
SKINLAB_REGISTER(metric, avg_l1, skinlab::eval::AvgL1);

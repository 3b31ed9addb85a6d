#include "framework/losses/mse.hpp"

#include "framework/core/registry.hpp"

namespace skinlab::losses {

MseLoss::Options MseLoss::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "loss 'mse'", kReservedKeys);
  f.optional("per_element", o.per_element);
  f.finish();
  return o;
}

torch::Tensor MseLoss::operator()(const LossInputs& in) const {
  check_pred_target(in, "mse");
  const torch::Tensor squared = (in.pred - in.target).square();
  return options_.per_element ? squared.mean() : squared.sum(1).mean();
}

}  // namespace skinlab::losses

SKINLAB_REGISTER(loss, mse, skinlab::losses::MseLoss);

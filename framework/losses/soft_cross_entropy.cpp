#include "framework/losses/soft_cross_entropy.hpp"

#include "framework/core/registry.hpp"

namespace skinlab::losses {

SoftCrossEntropyLoss::Options SoftCrossEntropyLoss::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "loss 'soft_cross_entropy'", kReservedKeys);
  f.optional("eps", o.eps).check(o.eps > 0 && o.eps < 1, "eps", "must be in (0, 1)");
  f.finish();
  return o;
}

torch::Tensor SoftCrossEntropyLoss::operator()(const LossInputs& in) const {
  check_pred_target(in, "soft_cross_entropy");
  return -(in.target * torch::log(in.pred.clamp_min(options_.eps))).sum(1).mean();
}

}  // namespace skinlab::losses

SKINLAB_REGISTER(loss, soft_cross_entropy, skinlab::losses::SoftCrossEntropyLoss);

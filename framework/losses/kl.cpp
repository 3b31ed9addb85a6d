#include "framework/losses/kl.hpp"

#include "framework/core/registry.hpp"

namespace skinlab::losses {

KlLoss::Options KlLoss::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "loss 'kl'", kReservedKeys);
  f.optional("eps", o.eps).check(o.eps > 0 && o.eps < 1, "eps", "must be in (0, 1)");
  f.finish();
  return o;
}

torch::Tensor KlLoss::operator()(const LossInputs& in) const {
  check_pred_target(in, "kl");
  const torch::Tensor& t = in.target;
  const torch::Tensor log_ratio = torch::log(t.clamp_min(options_.eps)) -
                                  torch::log(in.pred.clamp_min(options_.eps));
  // where(t > 0, ...) makes 0·log(0/w) exactly 0, also in the gradient.
  const torch::Tensor terms = torch::where(t > 0, t * log_ratio, torch::zeros_like(t));
  return terms.sum(1).mean();
}

}  // namespace skinlab::losses

SKINLAB_REGISTER(loss, kl, skinlab::losses::KlLoss);

#include "framework/losses/prior_kl.hpp"

#include "framework/core/registry.hpp"
#include "framework/core/text.hpp"
#include "framework/losses/kl.hpp"

namespace skinlab::losses {

PriorKlLoss::Options PriorKlLoss::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "loss 'prior_kl'", kReservedKeys);
  f.required("prior", o.prior).check(!o.prior.empty(), "prior", "must not be empty");
  f.optional("eps", o.eps).check(o.eps > 0 && o.eps < 1, "eps", "must be in (0, 1)");
  f.finish();
  return o;
}

torch::Tensor PriorKlLoss::operator()(const LossInputs& in) const {
  TORCH_CHECK(in.pred.defined() && in.pred.dim() == 2,
              "prior_kl: needs a #V×C prediction");
  const auto it = in.priors.find(options_.prior);
  TORCH_CHECK(it != in.priors.end(), "prior_kl: no '", options_.prior,
              "' prior to anchor to (the character has: ", joined_keys(in.priors),
              "); prepare the dataset with preprocess.priors: [{type: ", options_.prior, "}]");
  const torch::Tensor& p = it->second;
  TORCH_CHECK(p.sizes() == in.pred.sizes(), "prior_kl: prior shape ", p.sizes(),
              " differs from prediction shape ", in.pred.sizes());
  const torch::Tensor mass = p.sum(1, true);
  const torch::Tensor q = torch::where(mass > 0, p / mass.clamp_min(1e-30), torch::zeros_like(p));
  return KlLoss(KlLoss::Options{options_.eps})(LossInputs{in.pred, q});
}

}  // namespace skinlab::losses

SKINLAB_REGISTER(loss, prior_kl, skinlab::losses::PriorKlLoss);

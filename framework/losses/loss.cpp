#include "framework/losses/loss.hpp"

#include <algorithm>
#include <cmath>

#include "framework/core/registry.hpp"

namespace skinlab::losses {

void check_pred_target(const LossInputs& in, const char* loss_name) {
  TORCH_CHECK(in.pred.defined() && in.target.defined(), loss_name,
              ": needs both a prediction and a target");
  TORCH_CHECK(in.pred.dim() == 2, loss_name, ": prediction must be #V×C, got shape ",
              in.pred.sizes());
  TORCH_CHECK(in.pred.sizes() == in.target.sizes(), loss_name, ": prediction shape ",
              in.pred.sizes(), " differs from target shape ", in.target.sizes());
  TORCH_CHECK(in.pred.is_floating_point() && in.target.is_floating_point(), loss_name,
              ": prediction and target must be floating-point tensors");
}

LossSum LossSum::from(const config::Node& list) {
  if (!list.is_sequence() || list.size() == 0) {
    list.fail("expected a non-empty list of losses, e.g. [{type: kl, weight: 1.0}]");
  }
  LossSum sum;
  std::map<std::string, int> seen;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const config::Node entry = list[i];
    const std::string type = entry.required_type("loss");
    double weight = 1.0;
    if (entry.has("weight")) weight = entry["weight"].as<double>();
    if (!std::isfinite(weight) || weight < 0) entry["weight"].fail("must be a finite number ≥ 0");
    const int n = ++seen[type];
    sum.terms_.push_back(Term{n == 1 ? type : type + "#" + std::to_string(n), weight,
                              loss_registry().create(type, entry)});
    for (std::string& prior : sum.terms_.back().loss->priors()) {
      sum.priors_.push_back(std::move(prior));
    }
  }
  std::sort(sum.priors_.begin(), sum.priors_.end());
  sum.priors_.erase(std::unique(sum.priors_.begin(), sum.priors_.end()), sum.priors_.end());
  return sum;
}

torch::Tensor LossSum::operator()(const LossInputs& in, std::map<std::string, double>* parts) const {
  torch::Tensor total;
  for (const auto& term : terms_) {
    torch::Tensor value = (*term.loss)(in);
    if (parts) (*parts)[term.name] = value.item<double>();
    value = value * term.weight;
    total = total.defined() ? total + value : value;
  }
  return total;
}

}  // namespace skinlab::losses

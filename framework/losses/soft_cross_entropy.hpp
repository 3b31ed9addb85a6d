#pragma once
/// \file
/// `soft_cross_entropy`: −Σ_c ŵ_c log w_c against soft (non one-hot) targets, the skinning loss
/// of RigNet (Xu et al. 2020, Sec. 3.3) and NeuroSkinning. It equals `kl` plus the target's
/// entropy, so it has the same gradient; baselines use it to match their papers' reported loss
/// values. Predictions are clamped to `eps` inside the log. Mean over vertices.

#include "framework/losses/loss.hpp"

namespace skinlab::losses {

class SoftCrossEntropyLoss final : public Loss {
 public:
  struct Options {
    double eps = 1e-8;  ///< lower clamp of predictions inside the log
    static Options from(const config::Node& node);
  };
  explicit SoftCrossEntropyLoss(Options options) : options_(options) {}
  torch::Tensor operator()(const LossInputs& in) const override;

 private:
  Options options_;
};

}  // namespace skinlab::losses

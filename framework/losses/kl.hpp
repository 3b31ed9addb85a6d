#pragma once
/// \file
/// `kl`: the data term L_D of HeterSkinNet (Pan et al. 2021, Sec. 3.4, Eq. 6), treating each
/// vertex's weights over its C candidate bones as a label distribution (Liu et al. 2019).
///
/// Direction: we minimise KL(ŵ ‖ w) = Σ_c ŵ_c log(ŵ_c / w_c), ground truth ŵ first. The paper
/// prints Σ w log(w/ŵ) (prediction first), which is infinite wherever the ground truth is 0 and
/// the prediction is not, i.e. on almost every vertex's non-influential candidate bones; the
/// label-distribution formulation it cites uses the ground-truth-first direction, as we do.
/// Zero ground-truth weights contribute 0 (the limit of t·log t); predictions are clamped to
/// `eps` inside the log so a zero prediction under a positive target stays finite.
/// Result: mean over vertices of the per-vertex divergence.

#include "framework/losses/loss.hpp"

namespace skinlab::losses {

class KlLoss final : public Loss {
 public:
  struct Options {
    double eps = 1e-8;  ///< lower clamp of predictions inside the log
    static Options from(const config::Node& node);
  };
  explicit KlLoss(Options options) : options_(options) {}
  torch::Tensor operator()(const LossInputs& in) const override;

 private:
  Options options_;
};

}  // namespace skinlab::losses

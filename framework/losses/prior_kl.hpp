#pragma once
/// \file
/// `prior_kl`: an anchor to a classical method's weights (not in the papers), for models that
/// start from a prior (experiments/heterskinnet/heterskinnet.hpp, "A prior"):
///
///     L_P = mean_v KL(q_v ‖ w_v),   q_v = p_v / Σ_c p_vc
///
/// where p_v is the prior's weight on the row's C entries (`LossInputs::priors[prior]`, zero
/// outside the K candidates) and w_v the prediction. q_v is what a zero head outputs (up to the
/// prior's ε), so L_P measures how far the learned correction moves away from the prior. A row
/// whose prior is zero on every entry contributes 0 (nothing to anchor to).
///
/// Why: trained without 0 A.D., the prior model's correction made 0 A.D.'s weights worse than
/// the prior alone (L1 0.725 vs 0.681, results/tables/generalisation_prior.md): what the
/// network learns where artists depart from bone heat on some games does not carry over to
/// others. With weight β next to the data term `kl`, the per-vertex optimum is the mixture
/// (ŵ + β q) / (1 + β) (the gradient of Σ kl + β L_P is that of `kl` against the mixed target),
/// i.e. a correction shrunk towards the prior by 1 / (1 + β) where the data is ambiguous.
/// Measured with β = 0.5 on that split (three seeds; the unanchored model two): L1 0.669 against
/// 0.711 unanchored and 0.693 for bone heat (results/tables/prior_anchor_zeroad.md).
/// Result: mean over vertices, like every loss (loss.hpp).

#include <string>
#include <vector>

#include "framework/losses/loss.hpp"

namespace skinlab::losses {

class PriorKlLoss final : public Loss {
 public:
  struct Options {
    std::string prior;  ///< the prior's name, e.g. "bone_heat" (required)
    double eps = 1e-8;  ///< lower clamp of predictions inside the log
    static Options from(const config::Node& node);
  };
  explicit PriorKlLoss(Options options) : options_(std::move(options)) {}
  torch::Tensor operator()(const LossInputs& in) const override;
  std::vector<std::string> priors() const override { return {options_.prior}; }

 private:
  Options options_;
};

}  // namespace skinlab::losses

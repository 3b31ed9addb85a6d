#pragma once
/// \file
/// `laplacian_smoothing`: the smoothing term L_S of HeterSkinNet (Pan et al. 2021, Sec. 3.4,
/// Eq. 6): Σ_j w_jᵀ L w_j over the weight columns w_j (#V) of every bone, with L the #V×#V mesh
/// Laplacian (positive semi-definite convention, L = D − A or the cotangent Laplacian), divided
/// by #V to match the per-vertex mean of the data term. Computed as sum(W ⊙ (L W)), one sparse
/// product. Needs `LossInputs::laplacian`; the target is not used.

#include "framework/losses/loss.hpp"

namespace skinlab::losses {

class LaplacianSmoothingLoss final : public Loss {
 public:
  struct Options {
    static Options from(const config::Node& node);
  };
  explicit LaplacianSmoothingLoss(Options) {}
  torch::Tensor operator()(const LossInputs& in) const override;
};

}  // namespace skinlab::losses

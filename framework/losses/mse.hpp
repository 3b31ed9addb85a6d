#pragma once
/// \file
/// `mse`: mean over vertices of the squared L2 distance between prediction and target rows,
/// (1/#V) Σ_i ‖p_i − t_i‖². Used for per-vertex displacements (DenseGATs, Li et al. 2020,
/// Sec. 3.4) and as a plain regression baseline for weights. With `per_element: true` it is the
/// mean over all #V×C entries instead (torch's `mse_loss`).

#include "framework/losses/loss.hpp"

namespace skinlab::losses {

class MseLoss final : public Loss {
 public:
  struct Options {
    bool per_element = false;  ///< divide by #V·C instead of #V
    static Options from(const config::Node& node);
  };
  explicit MseLoss(Options options) : options_(options) {}
  torch::Tensor operator()(const LossInputs& in) const override;

 private:
  Options options_;
};

}  // namespace skinlab::losses

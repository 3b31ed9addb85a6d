#include "framework/losses/laplacian_smoothing.hpp"

#include "framework/core/registry.hpp"

namespace skinlab::losses {

LaplacianSmoothingLoss::Options LaplacianSmoothingLoss::Options::from(const config::Node& node) {
  config::Fields(node, "loss 'laplacian_smoothing'", kReservedKeys).finish();
  return {};
}

torch::Tensor LaplacianSmoothingLoss::operator()(const LossInputs& in) const {
  const torch::Tensor& w = in.pred;
  const torch::Tensor& lap = in.laplacian;
  TORCH_CHECK(w.defined() && w.dim() == 2, "laplacian_smoothing: prediction must be #V×C");
  TORCH_CHECK(lap.defined(), "laplacian_smoothing: needs the mesh Laplacian (LossInputs::laplacian)");
  TORCH_CHECK(lap.dim() == 2 && lap.size(0) == w.size(0) && lap.size(1) == w.size(0),
              "laplacian_smoothing: Laplacian must be #V×#V with #V = ", w.size(0), ", got ",
              lap.sizes());
  const torch::Tensor lw = lap.is_sparse() ? torch::mm(lap, w) : lap.matmul(w);
  return (w * lw).sum() / static_cast<double>(w.size(0));
}

}  // namespace skinlab::losses

SKINLAB_REGISTER(loss, laplacian_smoothing, skinlab::losses::LaplacianSmoothingLoss);

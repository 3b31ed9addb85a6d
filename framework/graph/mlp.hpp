#pragma once
/// \file
/// The multi-layer perceptron every graph op and the final layers of a model are made of
/// (HeterSkinNet Sec. 4.2): Linear layers, each followed by LeakyReLU(α = 0.2), weights
/// initialised Kaiming normal (He et al. 2015), optional dropout in front of every layer but the
/// first.
///
/// Choices where the paper is silent:
/// - Kaiming normal with fan_in and the gain of LeakyReLU(0.2), √(2 / (1 + 0.2²)), the
///   activation the weights feed (PyTorch's `kaiming_normal_(w, a=0.2, nonlinearity=
///   'leaky_relu')`); biases start at 0.
/// - The last layer is activated too unless `activate_last` is false: inside a convolution the
///   MLP is followed by an aggregation and the next layer, as in RigNet's and DGCNN's MLPs (and
///   it must be for EdgeConv's max to act on rectified messages); a model's output layer (the
///   logits of the softmax over K bones) sets it to false.
/// - Dropout (the 50% "in the final layers") is applied to the input of every layer except the
///   first, i.e. after each hidden activation, only in training mode.
/// - An empty width list is the identity (an op's optional MLP, e.g. `b2v` without one).

#include <torch/torch.h>

#include <cstdint>
#include <vector>

namespace skinlab::graph {

struct MlpOptions {
  std::vector<std::int64_t> widths;  ///< output width of each layer, all ≥ 1
  bool activate_last = true;         ///< LeakyReLU after the last layer as well
  double dropout = 0.0;              ///< drop probability in [0, 1) before layers 2..n (training)
};

class MlpImpl : public torch::nn::Module {
 public:
  /// Layers `linear0`, `linear1`, ... (checkpoint keys `linear<i>.weight`, `linear<i>.bias`).
  /// Throws c10::Error for an input width < 1, a width < 1 or a dropout outside [0, 1).
  MlpImpl(std::int64_t in_width, MlpOptions options);

  /// N×in → N×out.
  torch::Tensor forward(torch::Tensor x);
  /// Layers first..n-1 only, on N×width(first-1) input: lets a caller compute layer 0 its own
  /// way (EdgeConv factorises it, edge_conv.hpp) and hand over the activated result.
  torch::Tensor forward_from(std::size_t first, torch::Tensor x);
  /// The MLP on the rows of [own ‖ table[index(v,0)] ‖ … ‖ table[index(v,K−1)] ‖ shared] for
  /// #V×F₀ `own`, #B×F₁ `table`, #V×K int64 `index` and an optional 1×F₂ `shared` row (every
  /// row's; undefined for none): the input of b2v (Eq. 4) and of HeterSkinNet's head.
  ///
  /// Layer 0 is split by blocks of its weight:
  /// own·W₀ᵀ + Σ_k (table·W_kᵀ)[index(·,k)] + shared·W_sᵀ + b. This costs #B and 1 rows
  /// instead of #V for the gathered and shared blocks, and needs no #V×width concatenation,
  /// forward and backward: in HeterSkinNet's head (256 + 3×128 + 1024 inputs) layer 0's products
  /// shrink about 6× and the whole head, forward and backward, runs 2.3× faster (graph_ops_bench,
  /// BM_GatheredMlpHead: 889 → 394 ms CPU at 1 thread on 5K vertices).
  /// It is the same linear map, but the sums run in another order, so outputs (and gradients)
  /// differ from forward on the concatenation by float rounding (~1e-6 relative). Training runs
  /// made before this split was used with gradients (up to commit 0f80872) formed the
  /// concatenation.
  torch::Tensor forward_gathered(const torch::Tensor& own, const torch::Tensor& table,
                                 const torch::Tensor& index, const torch::Tensor& shared);
  /// Activation that follows layer `i` (identity for the last layer unless activate_last).
  torch::Tensor activation(std::size_t i, torch::Tensor y) const;

  std::size_t size() const { return linears_.size(); }
  std::int64_t in_width() const { return in_width_; }
  /// Width of the output: the last layer's, or the input width if there are no layers.
  std::int64_t out_width() const;
  torch::nn::Linear& linear(std::size_t i) { return linears_.at(i); }
  const MlpOptions& options() const { return options_; }

 private:
  std::int64_t in_width_;
  MlpOptions options_;
  std::vector<torch::nn::Linear> linears_;
};
TORCH_MODULE(Mlp);

/// Kaiming-normal weights (fan_in, LeakyReLU(0.2) gain) and zero bias, in place.
void kaiming_init(torch::nn::LinearImpl& linear);

}  // namespace skinlab::graph

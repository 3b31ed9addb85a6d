#pragma once
/// \file
/// `mean_conv`: the mesh convolution of the mesh-sequence BiLSTM (Qiao et al., Sec. 3.2, Eq. 2,
/// after Tan et al.'s mesh VAE and Duvenaud et al.'s graph convolution):
///
///     y_i = W1 x_i + W2 (Σ_{j∈N(i)} x_j) / d_i + b                     (Eq. 2)
///
/// with N(i) the one-ring and d_i = |N(i)|; a vertex without neighbours gets no neighbour term.
/// Then an activation (`tanh`, the paper's, or `none`). Updates the vertex features; the bone
/// features pass through.
///
/// `transpose: true` is the decoder's transpose mesh convolution (tCnv, Sec. 3.2): the
/// neighbour term is the adjoint Aᵀ of the encoder's neighbour mean A (A_ij = 1/d_i for
/// j ∈ N(i)), (Aᵀ x)_i = Σ_{k: i∈N(k)} x_k / d_k, each neighbour's value divided by its own
/// degree. W1, W2 and b are the layer's own (the paper does not say they are tied).
///
///     - {type: mean_conv, width: 64}                       # 9 → 64, tanh
///     - {type: mean_conv, width: 9, activation: none, transpose: true}
///
/// Options: `width` (output width, required), `activation` (tanh | none; default tanh),
/// `transpose` (default false), `edges` (a vertex edge set, default one_ring).
/// Parameters: `self.weight`, `self.bias` (W1, b) and `neighbours.weight` (W2).

#include "framework/graph/graph_op.hpp"

namespace skinlab::graph {

class MeanConv final : public GraphOp {
 public:
  struct Options {
    std::int64_t width = 0;
    bool tanh = true;
    bool transpose = false;
    EdgeSet edges = EdgeSet::kOneRing;
    static Options from(const config::Node& node);
  };
  explicit MeanConv(Options options);

  Features forward(const Features& in, const Graph& graph) override;
  std::string type() const override { return "mean_conv"; }
  const Options& options() const { return options_; }

 protected:
  Dims do_build(const Dims& in) override;

 private:
  Options options_;
  torch::nn::Linear self_{nullptr}, neighbours_{nullptr};
};

}  // namespace skinlab::graph

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
  /// The layer from the input `x` (#rows×in) and its neighbour term `aggregated` (the same
  /// shape: A x, or Aᵀ x when transposed), e.g. from `mean_operator`:
  /// activation(W1 x + W2 aggregated + b).
  torch::Tensor combine(const torch::Tensor& x, const torch::Tensor& aggregated);
  const Options& options() const { return options_; }

 protected:
  Dims do_build(const Dims& in) override;

 private:
  Options options_;
  torch::nn::Linear self_{nullptr}, neighbours_{nullptr};
};

/// The neighbour mean A of Eq. 2 over `edges` (#E×2 rows (i, j), i receiving from j) on `n`
/// vertices as a sparse #n×n float32 COO tensor (A_ij = 1/d_i), or its transpose Aᵀ: for a fixed
/// mesh, `torch::mm(A, X)` aggregates many feature columns at once (e.g. a batch of frames laid
/// side by side, #V×(B·C)), which is what the mesh-sequence network does.
torch::Tensor mean_operator(const torch::Tensor& edges, std::int64_t n, bool transpose);

}  // namespace skinlab::graph

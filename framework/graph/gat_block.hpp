#pragma once
/// \file
/// `gat_block`: the GAT block of DenseGATs (Li et al., "DenseGATs: A Graph-Attention-Based
/// Network for Nonlinear Character Deformation", I3D 2020, Sec. 3.2, Fig. 3), a graph-attention
/// aggregation stream (Veličković et al. 2018, GAT) concatenated with a self-reinforced linear
/// stream, on the vertex features over one mesh edge set:
///
///     z^k_i   = W^k g_i                                               (Eq. 1, head k = 1..K)
///     r_i     = H g_i                                                 (Eq. 2)
///     α^k_ij  = softmax over j ∈ N(i) of LeakyReLU(a^kᵀ [z^k_i ‖ z^k_j])  (Eq. 3)
///     out_i   = σ( ‖_k Σ_{j∈N(i)} α^k_ij z^k_j  ‖  r_i  + b )          (Eq. 4)
///
/// with σ = tanhshrink (x − tanh x) in the paper. Sec. 3.4's block, the default: K = 8 heads of
/// F = 8 features and β = 0.125, so 64 + 8 = 72 outputs; DenseGATs stacks such blocks densely
/// (Eq. 5), which is the model's business, as are its batch normalisations. The bone features
/// pass through.
///
///     - {type: gat_block}                              # 8 heads × 8 + round(0.125·64) = 72
///     - {type: gat_block, beta: 0}                     # "w/o self-reinforcement" ablation
///     - {type: gat_block, heads: 1, concat: false, activation: none}   # GAT's output layer
///
/// Options (every one validated at config time):
/// - `heads` K ≥ 1, default 8; `hidden` F ≥ 1, default 8.
/// - `beta` ≥ 0, default 0.125: the self-reinforced stream has round(β·K·F) features (round(β·F)
///   with `concat: false`); 0 drops the stream and H, and a β > 0 that rounds to 0 is an error.
///   (Eq. 2 writes H ∈ R^{βF×d}, but Fig. 3, the width KF + βKF of Eq. 4 and Sec. 3.4's "0.125
///   times the aggregation stream output feature size" make it βKF×d.)
/// - `edges`: one_ring (default) or geodesic; vertex features only.
/// - `self_loops`, default true: N(i) ∪ {i}, as GAT (a self-edge already in the list is dropped
///   first, so i counts once). Without, N(i) is the edge list as given, and a vertex without
///   edges gets a zero aggregation (out_i = σ(0 ‖ r_i + b)), never NaN.
/// - `concat`, default true: the heads concatenated (K·F wide, Eq. 4); false averages them
///   (F wide), as GAT's output layer.
/// - `activation` σ: tanhshrink (default, Eq. 4), elu (GAT between layers) or none (GAT's output).
/// - `negative_slope` of the LeakyReLU in Eq. 3, in [0, 1), default 0.2 (GAT).
/// Output width: (concat ? K·F : F) + round(β·(concat ? K·F : F)).
///
/// Parameters: `w.weight` ((K·F)×d: W^1..W^K stacked by rows, no bias, as GAT); `a_dst`, `a_src`
/// (K×F each: a^k = [a_dst[k] ‖ a_src[k]], the halves that multiply the receiver's z^k_i and the
/// neighbour's z^k_j); `h.weight` (round(βKF)×d, no bias; absent when β = 0); `bias` (one per
/// output, added before σ).
///
/// Our choices where the paper is silent: the output bias (GAT has one); Glorot-uniform init of
/// W, H and a, zero bias (GAT, PyG's GATConv); self-loops by default (GAT's convention, the
/// paper's "N(i)" does not say); the `concat: false` averaging and the elu/none activations are
/// GAT's, for ablations. GAT's dropout on inputs and attention is not part of the op.
///
/// Computation: whole-tensor ops only, on the receiver-sorted edge list with the self-loops
/// merged in (built each forward, no sort when the list is already sorted, as the dataset's are).
/// Per row (i, j): logit = LeakyReLU(s_dst[i] + s_src[j]) with s_·[n, k] = a_·[k]·z^k_n;
/// weight = exp(logit − max over i's rows) (`segment_extremum`, detached: the shift cancels);
/// then segment sums over each receiver's rows of the weights and of weight·z_j, and one
/// division per vertex and head. The receiver-side gathers have a segment-sum backward.

#include <cstdint>

#include "framework/graph/graph_op.hpp"

namespace skinlab::graph {

class GatBlock final : public GraphOp {
 public:
  enum class Activation { kTanhshrink, kElu, kNone };

  struct Options {
    std::int64_t heads = 8;   ///< K
    std::int64_t hidden = 8;  ///< F
    double beta = 0.125;      ///< β
    EdgeSet edges = EdgeSet::kOneRing;
    bool self_loops = true;
    bool concat = true;
    Activation activation = Activation::kTanhshrink;
    double negative_slope = 0.2;
    static Options from(const config::Node& node);

    /// K·F with concat, F without.
    std::int64_t aggregation_width() const { return concat ? heads * hidden : hidden; }
    /// round(β · aggregation_width()); 0 means no self-reinforced stream.
    std::int64_t self_width() const;
    std::int64_t out_width() const { return aggregation_width() + self_width(); }
  };

  /// The attention of every head on every edge the block aggregates over.
  struct Attention {
    /// #M×2 int64 (i, j), i receiving from j: sorted by receiver; with `self_loops` each
    /// receiver's (i, i) comes first, then its other edges in list order.
    torch::Tensor edges;
    /// #M×K α^k_ij (Eq. 3): the rows of each receiver sum to 1 in every column.
    torch::Tensor alpha;
  };

  explicit GatBlock(Options options);

  Features forward(const Features& in, const Graph& graph) override;
  /// The α of `forward` on the same input (same checks), e.g. for figures.
  Attention attention(const Features& in, const Graph& graph);
  std::string type() const override { return "gat_block"; }
  const Options& options() const { return options_; }

 protected:
  Dims do_build(const Dims& in) override;

 private:
  struct Attended;
  /// Checks `in` and `graph`, then computes z, the merged edges and α.
  Attended attend(const Features& in, const Graph& graph);

  Options options_;
  torch::nn::Linear w_{nullptr};
  torch::nn::Linear h_{nullptr};  ///< null when self_width() == 0
  torch::Tensor a_src_, a_dst_, bias_;
};

const char* to_string(GatBlock::Activation activation);

}  // namespace skinlab::graph

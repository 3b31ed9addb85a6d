#pragma once
/// \file
/// `v2b`: HeterSkinNet's vertex-to-bone convolution (Pan et al. 2021, Eq. 4 and Fig. 5; Eq. 4 is
/// garbled in one extraction of the paper, the other reads max, mean and var): each bone pools
/// the features of the vertices it influences and concatenates the statistics to its own,
///
///     f'_b = MLP(f_b ‖ max_{v∈I(b)} f_v ‖ mean_{v∈I(b)} f_v ‖ 0.1 · var_{v∈I(b)} f_v)
///
/// with I(b) = { v : b is among the top-K candidate bones of v } (A_ms[v, b] = 1, Sec. 3.2) and
/// the statistics taken per feature channel. The factor 0.1 on the variance is Sec. 4.2's "for
/// training stability". Updates the bone features (Fb + 3 Fv inputs to the MLP); the vertex
/// features pass through.
///
/// Definitions where the paper is silent:
/// - var is the population variance, mean((f_v − mean)²), which is defined (0) for a bone with a
///   single vertex, where the sample variance is not; computed in two passes (mean first), not
///   as E[f²] − E[f]², which cancels catastrophically for large, nearly equal features.
/// - A bone that is no vertex's candidate (I(b) = ∅, e.g. a short helper bone inside a larger
///   one) gets max = mean = var = 0: the MLP still sees its own feature, and no gradient flows
///   to any vertex through it.
/// - topk rows hold distinct bones (the dataset guarantees K ≤ #B and distinct candidates); a
///   repeated bone in one row would count that vertex twice.
///
///     - {type: v2b, mlp: [128], variance_scale: 0.1}
///
/// Options: `mlp` (default [128], the paper's bone local width; [] outputs the concatenation),
/// `variance_scale` (default 0.1, ≥ 0). Parameters: `mlp.linear<i>.*`.

#include "framework/graph/graph_op.hpp"
#include "framework/graph/mlp.hpp"

namespace skinlab::graph {

class V2b final : public GraphOp {
 public:
  struct Options {
    std::vector<std::int64_t> mlp = {128};
    double variance_scale = 0.1;
    static Options from(const config::Node& node);
  };
  explicit V2b(Options options) : options_(std::move(options)) {}

  Features forward(const Features& in, const Graph& graph) override;
  std::string type() const override { return "v2b"; }
  const Options& options() const { return options_; }

 protected:
  Dims do_build(const Dims& in) override;

 private:
  Options options_;
  Mlp mlp_{nullptr};
};

/// #B×3F: [max ‖ mean ‖ variance_scale · var] of the vertex features `x` (#V×F) over I(b) for each
/// bone b, from `topk_index` (#V×K, validated); zeros for a bone with I(b) = ∅. The pooling half
/// of `v2b`, exposed for tests and for models that pool without an MLP. Without gradients
/// (prediction, evaluation) it is one pass over the (vertex, candidate) pairs per statistic,
/// parallel over feature columns, with no #V·K×F row tensor; the sums run in the same order, so
/// the values are those of the differentiable form.
torch::Tensor pool_vertices_to_bones(const torch::Tensor& x, const torch::Tensor& topk_index,
                                     std::int64_t num_bones, double variance_scale);

}  // namespace skinlab::graph

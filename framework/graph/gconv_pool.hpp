#pragma once
/// \file
/// `gconv_pool`: the Graph Convolution Unit of NeuroSkinning (Liu et al., "NeuroSkinning:
/// Automatic Skin Binding for Production Characters with Deep Graph Networks", SIGGRAPH 2019,
/// Fig. 3 of the paper, also `imgs/pipeline.jpg` of github.com/FuxiCV/NeuroSkinning): a graph
/// convolution of the input, a graph pooling of its result over the same neighbourhood, and
/// both concatenated to the input (output width F + 2·F_h, the figure's `Nx(2f_h+f_in)`):
///
///     h_i   = MLP( mean over j ∈ N(i) ∪ {i} of x_j )       graph convolution
///     p_i   = max over j ∈ N(i) ∪ {i} of h_j                graph pooling
///     out_i = x_i ‖ h_i ‖ p_i
///
/// The figure fixes the structure and the widths, not the convolution's formula; we read it as
/// the mean-normalised GCN of Kipf & Welling (2017) on the mesh adjacency matrix with self-loops
/// (the `N×N` adjacency the figure feeds every unit), which is the op's one assumption. Updates
/// the vertex features; the bone features pass through. NeuroSkinning is the Table 3 row of
/// HeterSkinNet (Sec. 4.5), baselines/neuroskinning/.
///
///     - {type: gconv_pool, mlp: [256]}          # 64 → 64 + 2·256 = 576, as the figure
///
/// Options:
/// - `edges`: one vertex edge set, default one_ring (the mesh adjacency).
/// - `mlp`: widths of the convolution's MLP, default [256]; its last width is F_h.
/// Parameters: `mlp.linear<i>.*`.

#include "framework/graph/graph_op.hpp"
#include "framework/graph/mlp.hpp"

namespace skinlab::graph {

class GconvPool final : public GraphOp {
 public:
  struct Options {
    EdgeSet edges = EdgeSet::kOneRing;
    std::vector<std::int64_t> mlp = {256};
    static Options from(const config::Node& node);
  };
  explicit GconvPool(Options options) : options_(std::move(options)) {}

  Features forward(const Features& in, const Graph& graph) override;
  std::string type() const override { return "gconv_pool"; }
  const Options& options() const { return options_; }

 protected:
  Dims do_build(const Dims& in) override;

 private:
  Options options_;
  Mlp mlp_{nullptr};
};

}  // namespace skinlab::graph

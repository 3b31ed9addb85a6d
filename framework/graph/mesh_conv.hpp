#pragma once
/// \file
/// `mesh_conv`: HeterSkinNet's intra-graph convolution of the Mesh Graph (Pan et al. 2021,
/// Eq. 3), adopted from RigNet's GCU (Xu et al. 2020): EdgeConv separately over the one-ring
/// and the geodesic neighbours, concatenated, then an MLP:
///
///     f'_i = MLP(EdgeConv(v_i, N_m(v_i)) ‖ EdgeConv(v_i, N_g(v_i)))
///
/// Each EdgeConv has its own weights and is `edge_conv_max` (aggregate.hpp: max aggregation,
/// self-loop included). Updates the vertex features; the bone features pass through.
///
///     - {type: mesh_conv, edge_mlp: [256], mlp: [256]}
///
/// Options (defaults: the paper's vertex local width 256, Sec. 4.2):
/// - `edges`: the edge sets, in concatenation order; default [one_ring, geodesic]; one set
///   gives an ablation (e.g. [one_ring]: no geodesic branch); vertex sets only, no repeats.
/// - `edge_mlp`: widths of each EdgeConv's MLP, default [256] (one layer, F'v outputs each).
/// - `mlp`: widths of the fusing MLP on the concatenation, default [256] (the paper's
///   W_v ∈ R^{2F'v×F'v}); [] outputs the concatenation itself.
/// - `self_loops`: default true.
/// Parameters: `edge_mlp_<set>.linear<i>.*` and `mlp.linear<i>.*`.

#include "framework/graph/graph_op.hpp"
#include "framework/graph/mlp.hpp"

namespace skinlab::graph {

class MeshConv final : public GraphOp {
 public:
  struct Options {
    std::vector<EdgeSet> edges = {EdgeSet::kOneRing, EdgeSet::kGeodesic};
    std::vector<std::int64_t> edge_mlp = {256};
    std::vector<std::int64_t> mlp = {256};
    bool self_loops = true;
    static Options from(const config::Node& node);
  };
  explicit MeshConv(Options options) : options_(std::move(options)) {}

  Features forward(const Features& in, const Graph& graph) override;
  std::string type() const override { return "mesh_conv"; }
  const Options& options() const { return options_; }

 protected:
  Dims do_build(const Dims& in) override;

 private:
  Options options_;
  std::vector<Mlp> edge_mlps_;  ///< one per entry of options_.edges
  Mlp mlp_{nullptr};
};

}  // namespace skinlab::graph

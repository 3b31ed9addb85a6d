#pragma once
/// \file
/// `edge_conv`: EdgeConv (Wang et al. 2019, DGCNN) with max aggregation on one edge set,
/// HeterSkinNet's intra-graph convolution of the Skeleton Graph (Pan et al. 2021, Eq. 2):
///
///     f'_i = max over j in N(i) of MLP(f_i ‖ (f_i − f_j))
///
/// On `skeleton` it updates the bone features (N(b_i): bones sharing a joint with b_i,
/// `skeleton_edges`); on `one_ring` or `geodesic` it updates the vertex features (one branch of
/// Eq. 3; `mesh_conv` is the full mesh component). The other node type passes through.
/// N(i) includes i itself (`self_loops`, default), so a node without neighbours, e.g. a bone of a
/// one-bone skeleton or a vertex whose edges were all dropped, gets MLP(f_i ‖ 0); see
/// `edge_conv_max` in aggregate.hpp for the rule and how it is computed.
///
///     - {type: edge_conv, edges: skeleton, mlp: [128]}
///
/// Options: `edges` (required: one_ring, geodesic or skeleton); `mlp` (required, ≥ 1 layer:
/// widths, the last is the output width; Eq. 2's W_s ∈ R^{2F×F'} is one layer); `self_loops`
/// (default true). Parameters: `mlp.linear<i>.{weight,bias}`.

#include "framework/graph/graph_op.hpp"
#include "framework/graph/mlp.hpp"

namespace skinlab::graph {

class EdgeConv final : public GraphOp {
 public:
  struct Options {
    EdgeSet edges = EdgeSet::kSkeleton;
    std::vector<std::int64_t> mlp;
    bool self_loops = true;
    static Options from(const config::Node& node);
  };
  explicit EdgeConv(Options options) : options_(std::move(options)) {}

  Features forward(const Features& in, const Graph& graph) override;
  std::string type() const override { return "edge_conv"; }
  const Options& options() const { return options_; }

 protected:
  Dims do_build(const Dims& in) override;

 private:
  Options options_;
  Mlp mlp_{nullptr};
};

}  // namespace skinlab::graph

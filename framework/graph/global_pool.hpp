#pragma once
/// \file
/// `global_pool`: the global branch of HeterSkinNet (Pan et al. 2021, Sec. 3 and Fig. 3): "The
/// global branch of each subgraph consists of a max-pooling layer and an MLP layer, which extracts
/// the overall feature of the corresponding subgraph", and at the end "the bone nodes' features
/// are scattered to their neighboring vertex nodes with the concatenation of the two subgraphs'
/// global features". Per pooled subgraph s (vertices, bones):
///
///     g_s = max over nodes n of s of MLP_s(f_n)        (order mlp_max, default)
///     g_s = MLP_s(max over nodes n of s of f_n)        (order max_mlp)
///
/// and G = g_vertex ‖ g_bone (in `pool` order) is broadcast to every node of each type in `to`
/// and appended to its features (`keep_input`, default) or replaces them (`keep_input: false`:
/// the op's output is the branch itself, for a model that runs the local branch separately and
/// concatenates at the end, as Fig. 3 does). Node types not in `to` pass through.
///
/// Order. The sentence lists max-pooling first, but the per-node MLP before the max is the
/// PointNet/RigNet global feature (RigNet's skinning network, whose GCU the paper adopts for
/// Eq. 3, applies `MLP([512, 512, 1024])` per vertex and then `scatter_max`): a max over raw
/// local features followed by an MLP on one vector can only combine channel-wise maxima, while
/// MLP-then-max lets each channel be a learned function of a node's whole feature. `mlp_max` is
/// therefore the default and `max_mlp` the literal reading, one config line apart.
///
///     - {type: global_pool, vertex_mlp: [512], bone_mlp: [512], to: [vertex]}
///
/// Options: `pool` ([vertex, bone]; which subgraphs give a global feature), `vertex_mlp`
/// ([512], the paper's global vertex width), `bone_mlp` ([512], its global bone width; [] pools
/// the raw features), `order` (mlp_max | max_mlp), `to` ([vertex]), `keep_input` (true).
/// Parameters: `vertex_mlp.linear<i>.*`, `bone_mlp.linear<i>.*`.

#include "framework/graph/graph_op.hpp"
#include "framework/graph/mlp.hpp"

namespace skinlab::graph {

class GlobalPool final : public GraphOp {
 public:
  enum class Node { kVertex, kBone };
  struct Options {
    std::vector<Node> pool = {Node::kVertex, Node::kBone};
    std::vector<std::int64_t> vertex_mlp = {512};
    std::vector<std::int64_t> bone_mlp = {512};
    bool mlp_first = true;  ///< order: mlp_max (true) or max_mlp (false)
    std::vector<Node> to = {Node::kVertex};
    bool keep_input = true;
    static Options from(const config::Node& node);
  };
  explicit GlobalPool(Options options) : options_(std::move(options)) {}

  Features forward(const Features& in, const Graph& graph) override;
  std::string type() const override { return "global_pool"; }
  const Options& options() const { return options_; }

 protected:
  Dims do_build(const Dims& in) override;

 private:
  bool receives(Node node) const;
  Options options_;
  Mlp vertex_mlp_{nullptr}, bone_mlp_{nullptr};
  std::int64_t global_width_ = 0;
};

}  // namespace skinlab::graph

#pragma once
/// \file
/// Interface of the `graph_op` registry: one layer of a network on HeterSkinNet's heterogeneous
/// graph (Pan et al. 2021, Sec. 3.2–3.3, Fig. 3 and 5), i.e. a Mesh Graph of #V vertex nodes, a
/// Skeleton Graph of #B bone nodes and the vertex–bone connections of the top-K candidates.
///
/// Every op maps the features of both node types to new features of both node types,
///
///     Features{vertex #V×Fv, bone #B×Fb}  --op(graph)-->  Features{vertex #V×Fv', bone #B×Fb'}
///
/// updating the vertex features, the bone features or both and passing the rest through, so a
/// model is a sequence (or a small DAG) of ops read from its config, and an ablation such as
/// "no inter-graph convolutions" is a config that leaves the `b2v`/`v2b` entries out.
///
/// Life cycle (two phases, because widths are only known where the op sits in a model):
/// 1. The registry constructs the op from its config node, which holds only options (MLP widths,
///    edge set, ...); a misspelled or invalid option is a ConfigError before any work starts.
/// 2. The owning module registers it as a submodule and calls `build(in)` once with the input
///    widths; `build` registers the op's parameters and returns its output widths, which are the
///    next op's input widths.
/// 3. `forward(features, graph)` runs it; the op checks the widths it was built for, the graph's
///    index tensors it uses, and throws c10::Error (TORCH_CHECK) with the op's name, the tensor and
///    the offending edge, vertex or bone otherwise.
///
/// How a model builds ops from its config. A list of op nodes is a `Sequence` (as `LossSum::from`
/// turns a `losses:` list into plug-ins):
///
///     # configs/heterskinnet.yaml (sketch)
///     model:
///       type: heterskinnet
///       top_k: 3
///       edge_dropout: {p: 0.85, edges: [one_ring, geodesic]}
///       stem:                       # Fig. 3: inter-graph conv, then the two intra-graph convs
///         - {type: b2v, mlp: [256]}
///         - {type: v2b, mlp: [128]}
///         - {type: mesh_conv, edge_mlp: [256], mlp: [256]}
///         - {type: edge_conv, edges: skeleton, mlp: [128]}
///       global: {type: global_pool, vertex_mlp: [512], bone_mlp: [512], keep_input: false}
///       local: [...]                # alternately stacked intra- and inter-graph convs
///
///     // experiments/heterskinnet/heterskinnet.cpp (sketch)
///     stem_ = register_module("stem", graph::Sequence::from(node["stem"]));
///     global_ = register_module("global", graph::graph_op_from(node["global"]));
///     local_ = register_module("local", graph::Sequence::from(node["local"]));
///     graph::Dims d = stem_->build({/*vertex*/ k + 3, /*bone*/ 6, /*top_k*/ k});
///     graph::Dims g = global_->build(d);
///     d = local_->build(d);
///     ...
///     graph::Graph graph = graph::make_graph(character);   // once per character
///     if (is_training()) graph = graph::drop_edges(graph, options.edge_dropout);
///     graph::Features x = stem_->forward({vertex_attributes, bone_attributes}, graph);
///     graph::Features glob = global_->forward(x, graph), loc = local_->forward(x, graph);
///
/// Submodules are registered under stable names (`<index>_<type>` in a Sequence, `mlp`,
/// `edge_mlp_<set>` inside an op), so checkpoint keys follow the config.
///
/// Every op is written with whole-tensor gathers (`index_select`) and reductions over the index
/// tensors (`segment_reduce` on receiver-sorted rows, `index_add`; aggregate.hpp), never a loop
/// over vertices or edges, and works in any floating dtype (float32 for training, float64 for
/// gradient checks). Ops are deterministic on the CPU for a given input.

#include <torch/torch.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/tensors/tensors.hpp"

namespace skinlab::graph {

/// LeakyReLU slope of every hidden layer (HeterSkinNet Sec. 4.2: α = 0.2).
inline constexpr double kLeakySlope = 0.2;

/// Feature widths of the two node types, and K (candidate bones per vertex), which fixes the
/// input width of `b2v`. A width of 0 means "no features of this node type".
struct Dims {
  std::int64_t vertex = 0;  ///< Fv
  std::int64_t bone = 0;    ///< Fb
  std::int64_t top_k = 0;   ///< K; ops never change it
  bool operator==(const Dims& o) const {
    return vertex == o.vertex && bone == o.bone && top_k == o.top_k;
  }
};

/// Node features. Either tensor may be undefined when its width is 0.
struct Features {
  torch::Tensor vertex;  ///< #V×Fv floating
  torch::Tensor bone;    ///< #B×Fb floating
};

/// The edge sets of the heterogeneous graph an intra-graph op can run on.
enum class EdgeSet {
  kOneRing,   ///< mesh edges, N_m of Eq. 3 (vertex nodes)
  kGeodesic,  ///< geodesic neighbours within 0.06, N_g of Eq. 3 (vertex nodes)
  kSkeleton,  ///< bones sharing a joint, N(b_i) of Eq. 2 (bone nodes)
};
/// "one_ring", "geodesic", "skeleton": the config spelling.
const char* to_string(EdgeSet set);
/// Parses the config spelling; anything else is a ConfigError at `node` listing the three names.
EdgeSet parse_edge_set(const config::Node& node);
/// True for the skeleton (bone nodes), false for the two mesh edge sets (vertex nodes).
inline bool is_bone_set(EdgeSet set) { return set == EdgeSet::kSkeleton; }

/// The index tensors of one character's heterogeneous graph (int64, CPU). Edge lists are #E×2
/// rows (i, j): node i receives a message from its neighbour j (framework/tensors/tensors.hpp); the
/// mesh sets hold both directions of every edge, the geodesic set need not be symmetric.
struct Graph {
  torch::Tensor one_ring;    ///< #E×2 vertex–vertex mesh edges
  torch::Tensor geodesic;    ///< #E_g×2 vertex–vertex geodesic-neighbour edges
  torch::Tensor skeleton;    ///< #E_s×2 bone–bone edges (`skeleton_edges`)
  torch::Tensor topk_index;  ///< #V×K candidate bones of each vertex, nearest first (A_ms)
  std::int64_t num_vertices = 0;
  std::int64_t num_bones = 0;

  /// The edge list of `set` (possibly undefined if the caller did not fill it).
  const torch::Tensor& edges(EdgeSet set) const;
  std::int64_t top_k() const { return topk_index.defined() ? topk_index.size(1) : 0; }
  /// Checks every defined index tensor (shape, dtype, range) as the ops do; `who` prefixes the
  /// messages.
  void validate(const std::string& who = "graph") const;
};

/// #E_s×2 int64 bone–bone edges of the Skeleton Graph from the #B×2 (start, end) joints of the
/// bones (a helper bone has start = end). Rule: bones a ≠ b are adjacent when they share a joint,
/// both directions listed, sorted by (a, b); no self-edges.
///
/// The paper (Sec. 3.2) "treat[s] each bone as a node and each joint as an edge". Along a chain
/// every joint joins exactly two bones (the one ending and the one starting there), so a joint is
/// one edge. At a branching joint several bones meet, and "the joint as an edge" can only mean
/// connecting every pair of them (this is the line graph of the skeleton tree): the parent bone
/// with each child bone, and sibling bones with each other, which matches "N(b_i) is the set of
/// bones connecting to bone b_i" (Eq. 2). A leaf's zero-length helper bone (j, j) shares joint j
/// with the bone ending at j, so it hangs off the end of its limb. A skeleton with one bone has no
/// edges (EdgeConv's self-loop still gives it a defined output).
torch::Tensor skeleton_edges(const torch::Tensor& bone_joints);

/// The graph of a prepared character: its edge lists and candidates, and `skeleton_edges` of its
/// `bone_joints`. Validates the result (`Graph::validate`).
Graph make_graph(const data::CharacterTensors& character);

/// Checks the layer widths of an MLP option (`mlp: [256, 256]`) read at `key`: ConfigError at
/// `key` for a width < 1, or for an empty list unless `allow_empty`.
void check_widths(config::Fields& fields, const std::string& key,
                  const std::vector<std::int64_t>& widths, bool allow_empty);

// ---- argument checks shared by the ops (TORCH_CHECK, messages start with `op`) ----------------

/// `edges` is #E×2 int64 with every entry in [0, num_nodes); otherwise names the first bad edge,
/// e.g. "edge_conv: geodesic edge 17 is (5, 1203), but the graph has 1000 vertices".
void check_edges(const torch::Tensor& edges, std::int64_t num_nodes, const char* set_name,
                 const char* node_name, const std::string& op);
/// `graph.topk_index` is #V×k int64 with entries in [0, #B); names the first bad (vertex, slot).
void check_topk(const Graph& graph, std::int64_t k, const std::string& op);
/// `x` is a defined `rows`×`width` floating tensor; `what` is "vertex features" or "bone features".
void check_features(const torch::Tensor& x, std::int64_t rows, std::int64_t width, const char* what,
                    const std::string& op);

// ---- the interface -----------------------------------------------------------------------------

class GraphOp : public torch::nn::Module {
 public:
  /// Registers the parameters for inputs of widths `in` and returns the output widths. Called
  /// exactly once, before the first `forward`; a second call throws.
  Dims build(const Dims& in);
  /// Runs the op. Throws if not built, or if `in` or `graph` do not match (widths, #V, #B, K,
  /// index ranges).
  virtual Features forward(const Features& in, const Graph& graph) = 0;

  bool built() const { return built_; }
  const Dims& in_dims() const { return in_; }
  const Dims& out_dims() const { return out_; }
  /// The registry key ("edge_conv", ...), used in messages.
  virtual std::string type() const = 0;

 protected:
  /// The op's own part of `build`: checks it can run on `in` (e.g. `v2b` needs bone features),
  /// registers submodules and returns the output widths.
  virtual Dims do_build(const Dims& in) = 0;
  /// Throws unless built (names the op).
  void check_built() const;

 private:
  bool built_ = false;
  Dims in_{}, out_{};
};

/// Builds one op from a `{type: <key>, ...options}` node through the registry.
std::shared_ptr<GraphOp> graph_op_from(const config::Node& node);

/// A list of ops run one after the other; itself a GraphOp, so lists can be nested and a model
/// can treat a stage and a single op alike. Not a registry entry: it is what a config list is.
class Sequence final : public GraphOp {
 public:
  /// One op per entry of a config list (each `{type: ..., ...}`); the list may be empty (the
  /// identity, useful in ablations). A non-list is a ConfigError.
  static std::shared_ptr<Sequence> from(const config::Node& list);
  /// From already constructed (unbuilt) ops.
  explicit Sequence(std::vector<std::shared_ptr<GraphOp>> ops);

  Features forward(const Features& in, const Graph& graph) override;
  std::string type() const override { return "sequence"; }
  const std::vector<std::shared_ptr<GraphOp>>& ops() const { return ops_; }

 protected:
  Dims do_build(const Dims& in) override;

 private:
  std::vector<std::shared_ptr<GraphOp>> ops_;
};

}  // namespace skinlab::graph

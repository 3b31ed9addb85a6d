#include "framework/graph/graph_op.hpp"

#include "framework/core/registry.hpp"

namespace skinlab::graph {

const char* to_string(EdgeSet set) {
  switch (set) {
    case EdgeSet::kOneRing:
      return "one_ring";
    case EdgeSet::kGeodesic:
      return "geodesic";
    case EdgeSet::kSkeleton:
      return "skeleton";
  }
  return "?";
}

EdgeSet parse_edge_set(const config::Node& node) {
  const auto name = node.as<std::string>();
  for (EdgeSet set : {EdgeSet::kOneRing, EdgeSet::kGeodesic, EdgeSet::kSkeleton}) {
    if (name == to_string(set)) return set;
  }
  node.fail("unknown edge set '" + name + "'; known edge sets: one_ring, geodesic, skeleton");
}

const torch::Tensor& Graph::edges(EdgeSet set) const {
  switch (set) {
    case EdgeSet::kOneRing:
      return one_ring;
    case EdgeSet::kGeodesic:
      return geodesic;
    case EdgeSet::kSkeleton:
      return skeleton;
  }
  return one_ring;
}

void Graph::validate(const std::string& who) const {
  TORCH_CHECK(num_vertices >= 1, who, ": the graph has no vertices");
  TORCH_CHECK(num_bones >= 1, who, ": the graph has no bones");
  if (one_ring.defined()) check_edges(one_ring, num_vertices, "one_ring", "vertices", who);
  if (geodesic.defined()) check_edges(geodesic, num_vertices, "geodesic", "vertices", who);
  if (skeleton.defined()) check_edges(skeleton, num_bones, "skeleton", "bones", who);
  if (topk_index.defined()) check_topk(*this, topk_index.dim() == 2 ? topk_index.size(1) : -1, who);
}

torch::Tensor skeleton_edges(const torch::Tensor& bone_joints) {
  TORCH_CHECK(bone_joints.defined() && bone_joints.dim() == 2 && bone_joints.size(1) == 2,
              "skeleton_edges: bone_joints must be #B×2 (start, end joints), got shape ",
              bone_joints.defined() ? bone_joints.sizes() : c10::IntArrayRef{});
  TORCH_CHECK(bone_joints.scalar_type() == torch::kInt64,
              "skeleton_edges: bone_joints must be int64, got ", bone_joints.scalar_type());
  TORCH_CHECK(bone_joints.numel() == 0 || bone_joints.min().item<std::int64_t>() >= 0,
              "skeleton_edges: negative joint index in bone_joints");
  const std::int64_t nb = bone_joints.size(0);
  // share[a, b] = some joint of a equals some joint of b: (#B×1×2×1) == (1×#B×1×2), any over 2×2.
  const torch::Tensor j = bone_joints.cpu();
  torch::Tensor share = (j.view({nb, 1, 2, 1}) == j.view({1, nb, 1, 2})).flatten(2).any(2);
  share.fill_diagonal_(false);
  return share.nonzero().contiguous();  // row-major: sorted by (a, b)
}

Graph make_graph(const data::CharacterTensors& c) {
  Graph g;
  g.one_ring = c.one_ring;
  g.geodesic = c.geodesic;
  g.skeleton = skeleton_edges(c.bone_joints);
  g.topk_index = c.topk_index;
  g.num_vertices = c.num_vertices();
  g.num_bones = c.num_bones();
  g.validate("character '" + c.name + "'");
  return g;
}

void check_widths(config::Fields& fields, const std::string& key,
                  const std::vector<std::int64_t>& widths, bool allow_empty) {
  fields.check(allow_empty || !widths.empty(), key, "needs at least one layer width");
  for (std::int64_t w : widths) fields.check(w >= 1, key, "layer widths must be ≥ 1");
}

void check_edges(const torch::Tensor& edges, std::int64_t num_nodes, const char* set_name,
                 const char* node_name, const std::string& op) {
  TORCH_CHECK(edges.defined(), op, ": the graph has no ", set_name, " edges");
  TORCH_CHECK(edges.dim() == 2 && edges.size(1) == 2, op, ": ", set_name,
              " edges must be #E×2 (receiver, neighbour), got shape ", edges.sizes());
  TORCH_CHECK(edges.scalar_type() == torch::kInt64, op, ": ", set_name,
              " edges must be int64, got ", edges.scalar_type());
  if (edges.numel() == 0) return;
  // One reduction in the common case; the search for the culprit only when something is wrong.
  const auto [lo, hi] = torch::aminmax(edges);
  if (lo.item<std::int64_t>() >= 0 && hi.item<std::int64_t>() < num_nodes) return;
  const torch::Tensor bad = ((edges < 0) | (edges >= num_nodes)).any(1).nonzero();
  const std::int64_t e = bad[0][0].item<std::int64_t>();
  TORCH_CHECK(false, op, ": ", set_name, " edge ", e, " is (", edges[e][0].item<std::int64_t>(),
              ", ", edges[e][1].item<std::int64_t>(), "), but the graph has ", num_nodes, " ",
              node_name, " (valid indices 0..", num_nodes - 1, ")");
}

void check_topk(const Graph& graph, std::int64_t k, const std::string& op) {
  const torch::Tensor& t = graph.topk_index;
  TORCH_CHECK(t.defined(), op, ": the graph has no topk_index (candidate bones)");
  TORCH_CHECK(t.dim() == 2 && t.size(0) == graph.num_vertices, op,
              ": topk_index must be #V×K = ", graph.num_vertices, "×K, got shape ", t.sizes());
  TORCH_CHECK(t.size(1) == k, op, ": topk_index has K = ", t.size(1),
              " candidate bones per vertex, but the op was built for K = ", k);
  TORCH_CHECK(t.scalar_type() == torch::kInt64, op, ": topk_index must be int64, got ",
              t.scalar_type());
  if (t.numel() == 0) return;
  const auto [lo, hi] = torch::aminmax(t);
  if (lo.item<std::int64_t>() >= 0 && hi.item<std::int64_t>() < graph.num_bones) return;
  const torch::Tensor bad = ((t < 0) | (t >= graph.num_bones)).nonzero();
  const std::int64_t v = bad[0][0].item<std::int64_t>(), slot = bad[0][1].item<std::int64_t>();
  TORCH_CHECK(false, op, ": topk_index[", v, ", ", slot, "] = ", t[v][slot].item<std::int64_t>(),
              " (candidate ", slot, " of vertex ", v, ") is not a bone: the graph has ",
              graph.num_bones, " bones");
}

void check_features(const torch::Tensor& x, std::int64_t rows, std::int64_t width, const char* what,
                    const std::string& op) {
  TORCH_CHECK(x.defined(), op, ": needs ", what, " (", rows, "×", width, "), got none");
  TORCH_CHECK(x.dim() == 2, op, ": ", what, " must be a 2-D ", rows, "×", width,
              " tensor, got shape ", x.sizes());
  TORCH_CHECK(x.size(0) == rows, op, ": ", what, " have ", x.size(0), " rows, but the graph has ",
              rows);
  TORCH_CHECK(x.size(1) == width, op, ": ", what, " have width ", x.size(1),
              ", but the op was built for width ", width);
  TORCH_CHECK(x.is_floating_point(), op, ": ", what, " must be floating point, got ",
              x.scalar_type());
}

// ---- GraphOp ------------------------------------------------------------------------------------

Dims GraphOp::build(const Dims& in) {
  TORCH_CHECK(!built_, type(), ": build() called twice");
  TORCH_CHECK(in.vertex >= 0 && in.bone >= 0 && in.top_k >= 0, type(),
              ": negative input width (vertex ", in.vertex, ", bone ", in.bone, ", K ", in.top_k,
              ")");
  in_ = in;
  out_ = do_build(in);
  out_.top_k = in.top_k;
  built_ = true;
  return out_;
}

void GraphOp::check_built() const {
  TORCH_CHECK(built_, type(),
              ": forward() before build(); the owning model must call build() "
              "with the input widths first");
}

std::shared_ptr<GraphOp> graph_op_from(const config::Node& node) {
  return graph_op_registry().create(node);
}

// ---- Sequence -----------------------------------------------------------------------------------

std::shared_ptr<Sequence> Sequence::from(const config::Node& list) {
  if (list.exists() && !list.is_null() && !list.is_sequence()) {
    list.fail("expected a list of graph ops, e.g. [{type: b2v, mlp: [256]}, ...]");
  }
  std::vector<std::shared_ptr<GraphOp>> ops;
  for (std::size_t i = 0; i < list.size(); ++i) ops.push_back(graph_op_from(list[i]));
  return std::make_shared<Sequence>(std::move(ops));
}

Sequence::Sequence(std::vector<std::shared_ptr<GraphOp>> ops) : ops_(std::move(ops)) {
  for (std::size_t i = 0; i < ops_.size(); ++i) {
    TORCH_CHECK(ops_[i] != nullptr, "sequence: op ", i, " is null");
    register_module(std::to_string(i) + "_" + ops_[i]->type(), ops_[i]);
  }
}

Dims Sequence::do_build(const Dims& in) {
  Dims d = in;
  for (auto& op : ops_) d = op->build(d);
  return d;
}

Features Sequence::forward(const Features& in, const Graph& graph) {
  check_built();
  Features x = in;
  for (auto& op : ops_) x = op->forward(x, graph);
  return x;
}

}  // namespace skinlab::graph

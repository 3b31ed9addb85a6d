#include "framework/graph/global_pool.hpp"

#include <algorithm>

#include "framework/core/registry.hpp"

namespace skinlab::graph {

namespace {

std::vector<GlobalPool::Node> parse_nodes(const config::Node& list) {
  if (!list.is_sequence() || list.size() == 0) {
    list.fail("expected a non-empty list of node types, e.g. [vertex, bone]");
  }
  std::vector<GlobalPool::Node> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const auto name = list[i].as<std::string>();
    GlobalPool::Node node;
    if (name == "vertex") {
      node = GlobalPool::Node::kVertex;
    } else if (name == "bone") {
      node = GlobalPool::Node::kBone;
    } else {
      list[i].fail("unknown node type '" + name + "'; known node types: vertex, bone");
    }
    if (std::find(out.begin(), out.end(), node) != out.end()) {
      list[i].fail("node type '" + name + "' listed twice");
    }
    out.push_back(node);
  }
  return out;
}

/// 1×G global feature of one subgraph.
torch::Tensor pool(const torch::Tensor& x, MlpImpl& mlp, bool mlp_first) {
  TORCH_CHECK(x.size(0) >= 1, "global_pool: cannot max-pool over a subgraph with no nodes");
  if (mlp_first) return std::get<0>(mlp.forward(x).max(0, /*keepdim=*/true));
  return mlp.forward(std::get<0>(x.max(0, /*keepdim=*/true)));
}

}  // namespace

GlobalPool::Options GlobalPool::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "graph_op 'global_pool'");
  if (const config::Node n = f.section("pool"); n.exists()) o.pool = parse_nodes(n);
  f.optional("vertex_mlp", o.vertex_mlp);
  check_widths(f, "vertex_mlp", o.vertex_mlp, /*allow_empty=*/true);
  f.optional("bone_mlp", o.bone_mlp);
  check_widths(f, "bone_mlp", o.bone_mlp, /*allow_empty=*/true);
  std::string order = "mlp_max";
  f.optional("order", order)
      .check(order == "mlp_max" || order == "max_mlp", "order",
             "must be mlp_max (MLP per node, then max) or max_mlp (max, then MLP)");
  o.mlp_first = order == "mlp_max";
  if (const config::Node n = f.section("to"); n.exists()) o.to = parse_nodes(n);
  f.optional("keep_input", o.keep_input);
  f.finish();
  return o;
}

bool GlobalPool::receives(Node node) const {
  return std::find(options_.to.begin(), options_.to.end(), node) != options_.to.end();
}

Dims GlobalPool::do_build(const Dims& in) {
  global_width_ = 0;
  for (Node node : options_.pool) {
    const bool vertex = node == Node::kVertex;
    const std::int64_t width = vertex ? in.vertex : in.bone;
    TORCH_CHECK(width >= 1, type(), ": pools ", vertex ? "vertex" : "bone",
                " features, but their "
                "input width is 0");
    Mlp& mlp = vertex ? vertex_mlp_ : bone_mlp_;
    mlp = register_module(vertex ? "vertex_mlp" : "bone_mlp",
                          Mlp(width, MlpOptions{vertex ? options_.vertex_mlp : options_.bone_mlp}));
    global_width_ += mlp->out_width();
  }
  Dims out = in;
  if (receives(Node::kVertex)) out.vertex = (options_.keep_input ? in.vertex : 0) + global_width_;
  if (receives(Node::kBone)) out.bone = (options_.keep_input ? in.bone : 0) + global_width_;
  return out;
}

Features GlobalPool::forward(const Features& in, const Graph& graph) {
  check_built();
  const bool need_vertex = receives(Node::kVertex) && options_.keep_input;
  const bool need_bone = receives(Node::kBone) && options_.keep_input;
  std::vector<torch::Tensor> globals;
  for (Node node : options_.pool) {
    if (node == Node::kVertex) {
      check_features(in.vertex, graph.num_vertices, in_dims().vertex, "vertex features", type());
      globals.push_back(pool(in.vertex, *vertex_mlp_, options_.mlp_first));
    } else {
      check_features(in.bone, graph.num_bones, in_dims().bone, "bone features", type());
      globals.push_back(pool(in.bone, *bone_mlp_, options_.mlp_first));
    }
  }
  if (need_vertex) {
    check_features(in.vertex, graph.num_vertices, in_dims().vertex, "vertex features", type());
  }
  if (need_bone) check_features(in.bone, graph.num_bones, in_dims().bone, "bone features", type());
  const torch::Tensor global = globals.size() == 1 ? globals[0] : torch::cat(globals, 1);

  Features out = in;
  const auto receive = [&](const torch::Tensor& own, std::int64_t rows) {
    const torch::Tensor broadcast = global.expand({rows, global_width_});
    return options_.keep_input ? torch::cat({own, broadcast}, 1) : broadcast;
  };
  if (receives(Node::kVertex)) out.vertex = receive(in.vertex, graph.num_vertices);
  if (receives(Node::kBone)) out.bone = receive(in.bone, graph.num_bones);
  return out;
}

}  // namespace skinlab::graph

SKINLAB_REGISTER(graph_op, global_pool, skinlab::graph::GlobalPool);

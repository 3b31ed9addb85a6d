#include "framework/graph/edge_conv.hpp"

#include "framework/core/registry.hpp"
#include "framework/graph/aggregate.hpp"

namespace skinlab::graph {

EdgeConv::Options EdgeConv::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "graph_op 'edge_conv'");
  std::string edges;
  f.required("edges", edges);
  o.edges = parse_edge_set(node["edges"]);
  f.required("mlp", o.mlp);
  check_widths(f, "mlp", o.mlp, /*allow_empty=*/false);
  f.optional("self_loops", o.self_loops);
  f.finish();
  return o;
}

Dims EdgeConv::do_build(const Dims& in) {
  const bool bones = is_bone_set(options_.edges);
  const std::int64_t width = bones ? in.bone : in.vertex;
  TORCH_CHECK(width >= 1, type(), ": runs on ", to_string(options_.edges), " edges, so it needs ",
              bones ? "bone" : "vertex", " features, but their input width is 0");
  mlp_ = register_module("mlp", Mlp(2 * width, MlpOptions{options_.mlp}));
  Dims out = in;
  (bones ? out.bone : out.vertex) = mlp_->out_width();
  return out;
}

Features EdgeConv::forward(const Features& in, const Graph& graph) {
  check_built();
  const bool bones = is_bone_set(options_.edges);
  const char* set = to_string(options_.edges);
  Features out = in;
  if (bones) {
    check_features(in.bone, graph.num_bones, in_dims().bone, "bone features", type());
    check_edges(graph.edges(options_.edges), graph.num_bones, set, "bones", type());
    out.bone = edge_conv_max(in.bone, graph.edges(options_.edges), *mlp_, options_.self_loops);
  } else {
    check_features(in.vertex, graph.num_vertices, in_dims().vertex, "vertex features", type());
    check_edges(graph.edges(options_.edges), graph.num_vertices, set, "vertices", type());
    out.vertex = edge_conv_max(in.vertex, graph.edges(options_.edges), *mlp_, options_.self_loops);
  }
  return out;
}

}  // namespace skinlab::graph

SKINLAB_REGISTER(graph_op, edge_conv, skinlab::graph::EdgeConv);

#include "framework/graph/b2v.hpp"

#include "framework/core/registry.hpp"

namespace skinlab::graph {

B2v::Options B2v::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "graph_op 'b2v'");
  f.optional("mlp", o.mlp);
  check_widths(f, "mlp", o.mlp, /*allow_empty=*/true);
  f.finish();
  return o;
}

Dims B2v::do_build(const Dims& in) {
  TORCH_CHECK(in.vertex >= 1 && in.bone >= 1, type(),
              ": needs vertex and bone features, but the input widths are vertex ", in.vertex,
              ", bone ", in.bone);
  TORCH_CHECK(in.top_k >= 1, type(),
              ": needs K ≥ 1 candidate bones per vertex, got K = ", in.top_k);
  mlp_ = register_module("mlp", Mlp(in.vertex + in.top_k * in.bone, MlpOptions{options_.mlp}));
  Dims out = in;
  out.vertex = mlp_->out_width();
  return out;
}

Features B2v::forward(const Features& in, const Graph& graph) {
  check_built();
  check_features(in.vertex, graph.num_vertices, in_dims().vertex, "vertex features", type());
  check_features(in.bone, graph.num_bones, in_dims().bone, "bone features", type());
  check_topk(graph, in_dims().top_k, type());
  Features out = in;
  out.vertex = mlp_->forward_gathered(in.vertex, in.bone, graph.topk_index, torch::Tensor());
  return out;
}

}  // namespace skinlab::graph

SKINLAB_REGISTER(graph_op, b2v, skinlab::graph::B2v);

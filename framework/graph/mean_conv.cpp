#include "framework/graph/mean_conv.hpp"

#include "framework/core/registry.hpp"
#include "framework/graph/aggregate.hpp"

namespace skinlab::graph {

MeanConv::Options MeanConv::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "graph_op 'mean_conv'");
  f.required("width", o.width).check(o.width >= 1, "width", "must be ≥ 1");
  std::string activation = "tanh";
  f.optional("activation", activation)
      .check(activation == "tanh" || activation == "none", "activation",
             "unknown activation '" + activation + "'; known: tanh, none");
  o.tanh = activation == "tanh";
  f.optional("transpose", o.transpose);
  if (const config::Node set = f.section("edges"); set.exists()) {
    o.edges = parse_edge_set(set);
    if (is_bone_set(o.edges)) set.fail("mean_conv runs on a vertex edge set (one_ring, geodesic)");
  }
  f.finish();
  return o;
}

MeanConv::MeanConv(Options options) : options_(std::move(options)) {
  TORCH_CHECK(options_.width >= 1, type(), ": width must be ≥ 1, got ", options_.width);
}

Dims MeanConv::do_build(const Dims& in) {
  TORCH_CHECK(in.vertex >= 1, type(), ": needs vertex features, but their input width is 0");
  self_ = register_module("self", torch::nn::Linear(in.vertex, options_.width));
  neighbours_ = register_module(
      "neighbours", torch::nn::Linear(torch::nn::LinearOptions(in.vertex, options_.width).bias(false)));
  Dims out = in;
  out.vertex = options_.width;
  return out;
}

Features MeanConv::forward(const Features& in, const Graph& graph) {
  check_built();
  const std::int64_t n = graph.num_vertices;
  check_features(in.vertex, n, in_dims().vertex, "vertex features", type());
  const torch::Tensor& edges = graph.edges(options_.edges);
  check_edges(edges, n, to_string(options_.edges), "vertices", type());
  const torch::Tensor receiver = edges.select(1, 0), neighbour = edges.select(1, 1);
  const torch::Tensor& x = in.vertex;
  // The mean: row (i, j) sends x_j / d_i to i. Its adjoint: row (i, j) sends x_i / d_i to j.
  // Degrees are counted on receivers, so a row never divides by zero; a vertex no row reaches
  // gets 0.
  const torch::Tensor degree = count_rows(receiver, n, x.scalar_type());
  const torch::Tensor scale = degree.index_select(0, receiver).reciprocal().view({-1, 1});
  const torch::Tensor aggregated =
      options_.transpose
          ? scatter_rows(x.index_select(0, receiver) * scale, neighbour, n, "sum")
          : scatter_rows(x.index_select(0, neighbour) * scale, receiver, n, "sum");
  Features out = in;
  out.vertex = combine(x, aggregated);
  return out;
}

torch::Tensor MeanConv::combine(const torch::Tensor& x, const torch::Tensor& aggregated) {
  check_built();
  const torch::Tensor y = self_->forward(x) + neighbours_->forward(aggregated);
  return options_.tanh ? torch::tanh(y) : y;
}

torch::Tensor mean_operator(const torch::Tensor& edges, std::int64_t n, bool transpose) {
  check_edges(edges, n, "one_ring", "vertices", "mean_operator");
  const torch::Tensor receiver = edges.select(1, 0), neighbour = edges.select(1, 1);
  const torch::Tensor degree = count_rows(receiver, n, torch::kFloat32);
  const torch::Tensor values = degree.index_select(0, receiver).reciprocal();
  const torch::Tensor index = transpose ? torch::stack({neighbour, receiver}) : torch::stack({receiver, neighbour});
  return torch::sparse_coo_tensor(index, values, {n, n}).coalesce();
}

}  // namespace skinlab::graph

SKINLAB_REGISTER(graph_op, mean_conv, skinlab::graph::MeanConv);

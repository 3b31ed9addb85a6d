#include "framework/graph/gconv_pool.hpp"

#include "framework/core/registry.hpp"
#include "framework/graph/aggregate.hpp"

namespace skinlab::graph {

GconvPool::Options GconvPool::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "graph_op 'gconv_pool'");
  const config::Node set = f.section("edges");
  if (set.exists()) {
    o.edges = parse_edge_set(set);
    if (is_bone_set(o.edges)) set.fail("gconv_pool runs on a vertex edge set (one_ring, geodesic)");
  }
  f.optional("mlp", o.mlp);
  check_widths(f, "mlp", o.mlp, /*allow_empty=*/false);
  f.finish();
  return o;
}

Dims GconvPool::do_build(const Dims& in) {
  TORCH_CHECK(in.vertex >= 1, type(), ": needs vertex features, but their input width is 0");
  mlp_ = register_module("mlp", Mlp(in.vertex, MlpOptions{options_.mlp}));
  Dims out = in;
  out.vertex = in.vertex + 2 * mlp_->out_width();
  return out;
}

Features GconvPool::forward(const Features& in, const Graph& graph) {
  check_built();
  check_features(in.vertex, graph.num_vertices, in_dims().vertex, "vertex features", type());
  const torch::Tensor& edges = graph.edges(options_.edges);
  check_edges(edges, graph.num_vertices, to_string(options_.edges), "vertices", type());
  const std::int64_t n = graph.num_vertices;
  const torch::Tensor receiver = edges.select(1, 0), neighbour = edges.select(1, 1);
  const torch::Tensor& x = in.vertex;

  // Mean over the closed neighbourhood N(i) ∪ {i}: (x_i + Σ_j x_j) / (|N(i)| + 1).
  const torch::Tensor sum = scatter_rows(x.index_select(0, neighbour), receiver, n, "sum") + x;
  const torch::Tensor count = count_rows(receiver, n, x.scalar_type()).add(1).view({-1, 1});
  const torch::Tensor h = mlp_->forward(sum / count);

  // Max over the closed neighbourhood; an isolated vertex keeps its own h (−inf from the
  // empty segment loses to it).
  const Segments segments = Segments::of(receiver, n);
  const torch::Tensor pooled =
      torch::maximum(h, segment_extremum(segments.sorted(h.index_select(0, neighbour)), segments,
                                         segments.sorted_index(receiver), "max"));
  Features out = in;
  out.vertex = torch::cat({x, h, pooled}, 1);
  return out;
}

}  // namespace skinlab::graph

SKINLAB_REGISTER(graph_op, gconv_pool, skinlab::graph::GconvPool);

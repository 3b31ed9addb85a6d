#include "framework/graph/v2b.hpp"

#include <cmath>

#include "framework/core/registry.hpp"
#include "framework/graph/aggregate.hpp"

namespace skinlab::graph {

V2b::Options V2b::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "graph_op 'v2b'");
  f.optional("mlp", o.mlp);
  check_widths(f, "mlp", o.mlp, /*allow_empty=*/true);
  f.optional("variance_scale", o.variance_scale)
      .check(std::isfinite(o.variance_scale) && o.variance_scale >= 0, "variance_scale",
             "must be a finite number ≥ 0");
  f.finish();
  return o;
}

torch::Tensor pool_vertices_to_bones(const torch::Tensor& x, const torch::Tensor& topk_index,
                                     std::int64_t num_bones, double variance_scale) {
  const std::int64_t nv = x.size(0), k = topk_index.size(1), f = x.size(1);
  // One row per (vertex, candidate) pair: the vertex's feature, sent to the candidate bone.
  const torch::Tensor bone = topk_index.reshape({-1});
  const torch::Tensor rows = x.unsqueeze(1).expand({nv, k, f}).reshape({nv * k, f});
  const torch::Tensor count =
      count_rows(bone, num_bones, x.scalar_type()).clamp_min(1).view({-1, 1});
  const torch::Tensor max = scatter_rows(rows, bone, num_bones, "amax");
  const torch::Tensor mean = scatter_rows(rows, bone, num_bones, "sum") / count;
  const torch::Tensor deviation = rows - mean.index_select(0, bone);
  const torch::Tensor var = scatter_rows(deviation * deviation, bone, num_bones, "sum") / count;
  return torch::cat({max, mean, var * variance_scale}, 1);
}

Dims V2b::do_build(const Dims& in) {
  TORCH_CHECK(in.vertex >= 1 && in.bone >= 1, type(),
              ": needs vertex and bone features, but the input widths are vertex ", in.vertex,
              ", bone ", in.bone);
  TORCH_CHECK(in.top_k >= 1, type(),
              ": needs K ≥ 1 candidate bones per vertex, got K = ", in.top_k);
  mlp_ = register_module("mlp", Mlp(in.bone + 3 * in.vertex, MlpOptions{options_.mlp}));
  Dims out = in;
  out.bone = mlp_->out_width();
  return out;
}

Features V2b::forward(const Features& in, const Graph& graph) {
  check_built();
  check_features(in.vertex, graph.num_vertices, in_dims().vertex, "vertex features", type());
  check_features(in.bone, graph.num_bones, in_dims().bone, "bone features", type());
  check_topk(graph, in_dims().top_k, type());
  const torch::Tensor pooled =
      pool_vertices_to_bones(in.vertex, graph.topk_index, graph.num_bones, options_.variance_scale);
  Features out = in;
  out.bone = mlp_->forward(torch::cat({in.bone, pooled}, 1));
  return out;
}

}  // namespace skinlab::graph

SKINLAB_REGISTER(graph_op, v2b, skinlab::graph::V2b);

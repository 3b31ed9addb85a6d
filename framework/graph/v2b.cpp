#include "framework/graph/v2b.hpp"

#include <ATen/Parallel.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

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

namespace {

/// pool_vertices_to_bones without autograd: max, then sum → mean, then squared deviations →
/// var, each accumulated over the pairs in row-major (vertex, candidate) order as index_add
/// does, for a block of feature columns per thread.
torch::Tensor pool_without_gradients(const torch::Tensor& x, const torch::Tensor& topk_index,
                                     std::int64_t num_bones, double variance_scale) {
  const torch::Tensor xs = x.contiguous();
  const torch::Tensor index = topk_index.contiguous();
  const std::int64_t nv = xs.size(0), k = index.size(1), f = xs.size(1);
  std::vector<std::int64_t> count(static_cast<std::size_t>(num_bones), 0);
  const std::int64_t* bone = index.data_ptr<std::int64_t>();
  for (std::int64_t r = 0; r < nv * k; ++r) ++count[static_cast<std::size_t>(bone[r])];
  torch::Tensor out = torch::zeros({num_bones, 3 * f}, xs.options());
  AT_DISPATCH_FLOATING_TYPES(xs.scalar_type(), "pool_vertices_to_bones", [&] {
    const scalar_t* in = xs.data_ptr<scalar_t>();
    scalar_t* o = out.data_ptr<scalar_t>();
    const scalar_t scale = static_cast<scalar_t>(variance_scale);
    at::parallel_for(0, f, /*grain_size=*/32, [&](std::int64_t c0, std::int64_t c1) {
      const auto cell = [&](std::int64_t b, std::int64_t part, std::int64_t c) -> scalar_t& {
        return o[b * 3 * f + part * f + c];
      };
      for (std::int64_t b = 0; b < num_bones; ++b) {
        for (std::int64_t c = c0; c < c1; ++c) {
          cell(b, 0, c) = -std::numeric_limits<scalar_t>::infinity();
        }
      }
      for (std::int64_t r = 0; r < nv * k; ++r) {
        const scalar_t* row = in + (r / k) * f;
        for (std::int64_t c = c0; c < c1; ++c) {
          scalar_t& m = cell(bone[r], 0, c);
          m = row[c] > m ? row[c] : m;
          cell(bone[r], 1, c) += row[c];
        }
      }
      for (std::int64_t b = 0; b < num_bones; ++b) {
        const auto n = static_cast<scalar_t>(std::max<std::int64_t>(count[b], 1));
        for (std::int64_t c = c0; c < c1; ++c) {
          if (count[b] == 0) cell(b, 0, c) = 0;
          cell(b, 1, c) /= n;
        }
      }
      for (std::int64_t r = 0; r < nv * k; ++r) {
        const scalar_t* row = in + (r / k) * f;
        for (std::int64_t c = c0; c < c1; ++c) {
          const scalar_t d = row[c] - cell(bone[r], 1, c);
          cell(bone[r], 2, c) += d * d;
        }
      }
      for (std::int64_t b = 0; b < num_bones; ++b) {
        const auto n = static_cast<scalar_t>(std::max<std::int64_t>(count[b], 1));
        for (std::int64_t c = c0; c < c1; ++c) cell(b, 2, c) = cell(b, 2, c) / n * scale;
      }
    });
  });
  return out;
}

}  // namespace

torch::Tensor pool_vertices_to_bones(const torch::Tensor& x, const torch::Tensor& topk_index,
                                     std::int64_t num_bones, double variance_scale) {
  if (!(torch::GradMode::is_enabled() && x.requires_grad())) {
    return pool_without_gradients(x, topk_index, num_bones, variance_scale);
  }
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

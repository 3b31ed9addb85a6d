#pragma once
// Shared by the graph-op tests: a tiny heterogeneous graph with the awkward cases (a vertex with
// no neighbour, an asymmetric geodesic set, a branching skeleton with helper bones, a bone no
// vertex picks), element-wise access helpers, and a finite-difference gradient check.

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/graph/graph_op.hpp"
#include "framework/graph/mlp.hpp"

namespace skinlab::graph::testing {

inline torch::Tensor edge_tensor(const std::vector<std::pair<int64_t, int64_t>>& pairs) {
  torch::Tensor t = torch::empty({static_cast<int64_t>(pairs.size()), 2}, torch::kInt64);
  for (std::size_t e = 0; e < pairs.size(); ++e) {
    t[e][0] = pairs[e].first;
    t[e][1] = pairs[e].second;
  }
  return t;
}

/// Joints 0-1-2 and 1-3 (joint 1 branches); bones (0,1), (1,2), (1,3) and the helper bones of
/// the leaves 2 and 3.
inline torch::Tensor tiny_bone_joints() {
  return edge_tensor({{0, 1}, {1, 2}, {1, 3}, {2, 2}, {3, 3}});
}

struct TinyGraph {
  Graph graph;
  Features features;
  Dims dims;
};

/// 8 vertices (vertex 7 has no edge of any set), 5 bones (bone 4 is no vertex's candidate),
/// K = 2, features of widths fv and fb in `dtype`, seeded.
inline TinyGraph tiny_graph(int64_t fv = 3, int64_t fb = 2,
                            torch::ScalarType dtype = torch::kFloat64, uint64_t seed = 1) {
  torch::manual_seed(seed);
  TinyGraph t;
  Graph& g = t.graph;
  g.num_vertices = 8;
  g.num_bones = 5;
  // a strip of triangles 0..6, both directions
  std::vector<std::pair<int64_t, int64_t>> ring;
  for (auto [a, b] : std::vector<std::pair<int64_t, int64_t>>{
           {0, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 5}, {5, 6}, {0, 2}, {2, 4}, {4, 6}}) {
    ring.push_back({a, b});
    ring.push_back({b, a});
  }
  g.one_ring = edge_tensor(ring);
  // asymmetric, unsorted, with a self-edge (max is idempotent, so it must not matter)
  g.geodesic =
      edge_tensor({{0, 3}, {3, 0}, {0, 4}, {6, 1}, {1, 5}, {2, 6}, {5, 5}, {4, 0}, {3, 6}});
  g.skeleton = skeleton_edges(tiny_bone_joints());
  g.topk_index = edge_tensor({{0, 1}, {1, 0}, {1, 2}, {2, 1}, {2, 3}, {3, 2}, {3, 0}, {0, 3}});
  t.features.vertex = torch::randn({g.num_vertices, fv}, dtype);
  t.features.bone = torch::randn({g.num_bones, fb}, dtype);
  t.dims = Dims{fv, fb, 2};
  return t;
}

/// An op built from YAML for `dims`, converted to `dtype`.
inline std::shared_ptr<GraphOp> make_op(const std::string& yaml, const Dims& dims,
                                        torch::ScalarType dtype = torch::kFloat64) {
  auto op = graph_op_from(config::Config::parse(yaml, "test.yaml").root());
  op->build(dims);
  op->to(dtype);
  return op;
}

/// The MLP submodule `name` of `op` (e.g. "mlp", "edge_mlp_geodesic").
inline MlpImpl& mlp_of(GraphOp& op, const std::string& name) {
  for (const auto& item : op.named_children()) {
    if (item.key() == name) return *std::dynamic_pointer_cast<MlpImpl>(item.value());
  }
  throw std::runtime_error("no submodule " + name);
}

/// One row through the MLP, the plain way (no factorisation): 1-D in, 1-D out.
inline torch::Tensor apply_row(MlpImpl& mlp, const torch::Tensor& row) {
  return mlp.forward(row.unsqueeze(0)).squeeze(0);
}

/// Naive EdgeConv: a loop over nodes and their neighbours (Eq. 2), zero for no neighbour.
inline torch::Tensor naive_edge_conv(const torch::Tensor& x, const torch::Tensor& edges,
                                     MlpImpl& mlp, bool self_loops) {
  const int64_t n = x.size(0);
  std::vector<std::vector<int64_t>> neighbours(n);
  for (int64_t e = 0; e < edges.size(0); ++e) {
    neighbours[edges[e][0].item<int64_t>()].push_back(edges[e][1].item<int64_t>());
  }
  std::vector<torch::Tensor> rows;
  for (int64_t i = 0; i < n; ++i) {
    if (self_loops) neighbours[i].push_back(i);
    torch::Tensor best;
    for (int64_t j : neighbours[i]) {
      const torch::Tensor m = apply_row(mlp, torch::cat({x[i], x[i] - x[j]}));
      best = best.defined() ? torch::maximum(best, m) : m;
    }
    rows.push_back(best.defined() ? best : torch::zeros({mlp.out_width()}, x.options()));
  }
  return torch::stack(rows);
}

/// Σ out.vertex ⊙ Rv + Σ out.bone ⊙ Rb with fixed random Rv, Rb: a scalar that depends on every
/// output entry.
class Probe {
 public:
  explicit Probe(const Features& like) {
    torch::manual_seed(99);
    if (like.vertex.defined()) rv_ = torch::randn(like.vertex.sizes(), like.vertex.options());
    if (like.bone.defined()) rb_ = torch::randn(like.bone.sizes(), like.bone.options());
  }
  torch::Tensor operator()(const Features& out) const {
    torch::Tensor s = torch::zeros({}, torch::kFloat64);
    if (rv_.defined()) s = s + (out.vertex * rv_).sum();
    if (rb_.defined()) s = s + (out.bone * rb_).sum();
    return s;
  }

 private:
  torch::Tensor rv_, rb_;
};

/// Central finite differences (double precision) of Probe(op(features)) with respect to every
/// parameter and every input feature entry, compared with autograd.
inline void expect_gradients_match(GraphOp& op, const Features& features, const Graph& graph,
                                   double tol = 1e-6) {
  Features in{features.vertex.defined() ? features.vertex.detach().clone().requires_grad_(true)
                                        : torch::Tensor(),
              features.bone.defined() ? features.bone.detach().clone().requires_grad_(true)
                                      : torch::Tensor()};
  const Probe probe(op.forward(in, graph));
  std::vector<std::pair<std::string, torch::Tensor>> wrt;
  for (const auto& p : op.named_parameters()) wrt.push_back({p.key(), p.value()});
  if (in.vertex.defined()) wrt.push_back({"vertex features", in.vertex});
  if (in.bone.defined()) wrt.push_back({"bone features", in.bone});
  for (auto& [name, t] : wrt) {
    if (t.grad().defined()) t.mutable_grad().zero_();
  }
  probe(op.forward(in, graph)).backward();
  const double h = 1e-6;
  for (auto& [name, t] : wrt) {
    ASSERT_EQ(t.scalar_type(), torch::kFloat64) << name;
    const torch::Tensor analytic = t.grad().defined() ? t.grad().clone() : torch::zeros_like(t);
    torch::NoGradGuard no_grad;
    auto flat = t.view(-1);
    for (int64_t i = 0; i < flat.numel(); ++i) {
      const double saved = flat[i].item<double>();
      flat[i] = saved + h;
      const double plus = probe(op.forward(in, graph)).item<double>();
      flat[i] = saved - h;
      const double minus = probe(op.forward(in, graph)).item<double>();
      flat[i] = saved;
      const double numeric = (plus - minus) / (2 * h);
      const double a = analytic.view(-1)[i].item<double>();
      EXPECT_NEAR(a, numeric, tol * std::max(1.0, std::abs(numeric))) << name << " entry " << i;
    }
  }
}

}  // namespace skinlab::graph::testing

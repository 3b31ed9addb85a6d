// The mesh-sequence BiLSTM's mesh convolution (graph/mean_conv.hpp, Qiao et al. Eq. 2) against
// a per-vertex loop of the equation, its transpose as the exact adjoint of the neighbour mean
// (⟨A x, y⟩ = ⟨x, Aᵀ y⟩ on an asymmetric edge set), an isolated vertex, edge order, gradients,
// widths and option errors.

#include <gtest/gtest.h>

#include "framework/core/error.hpp"
#include "framework/graph/mean_conv.hpp"
#include "tests/graph/graph_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::graph {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using namespace skinlab::graph::testing;

torch::Tensor param(GraphOp& op, const std::string& name) {
  for (const auto& p : op.named_parameters()) {
    if (p.key() == name) return p.value();
  }
  ADD_FAILURE() << "no parameter " << name;
  return {};
}

/// Eq. 2 vertex by vertex: y_i = W1 x_i + W2 Σ_{j∈N(i)} x_j / d_i + b (no neighbour term when
/// d_i = 0); with `transpose`, the neighbour term is Σ over rows (k, i) of x_k / d_k.
torch::Tensor naive_mean_conv(const torch::Tensor& x, const torch::Tensor& edges, GraphOp& op,
                              bool transpose, bool tanh) {
  const int64_t n = x.size(0);
  std::vector<int64_t> degree(n, 0);
  for (int64_t e = 0; e < edges.size(0); ++e) ++degree[edges[e][0].item<int64_t>()];
  std::vector<torch::Tensor> aggregated(n, torch::zeros_like(x[0]));
  for (int64_t e = 0; e < edges.size(0); ++e) {
    const int64_t i = edges[e][0].item<int64_t>(), j = edges[e][1].item<int64_t>();
    if (transpose) {
      aggregated[j] = aggregated[j] + x[i] / static_cast<double>(degree[i]);
    } else {
      aggregated[i] = aggregated[i] + x[j] / static_cast<double>(degree[i]);
    }
  }
  const torch::Tensor W1 = param(op, "self.weight"), b = param(op, "self.bias"),
                      W2 = param(op, "neighbours.weight");
  std::vector<torch::Tensor> out;
  for (int64_t i = 0; i < n; ++i) {
    torch::Tensor y = W1.matmul(x[i]) + W2.matmul(aggregated[i]) + b;
    out.push_back(tanh ? torch::tanh(y) : y);
  }
  return torch::stack(out);
}

TEST(MeanConv, MatchesLoopReference) {
  const TinyGraph t = tiny_graph(3, 2);
  for (const std::string options :
       {"width: 4", "width: 5, activation: none", "width: 4, transpose: true",
        "width: 2, edges: geodesic, transpose: true, activation: none", "width: 3, edges: geodesic"}) {
    auto op = make_op("{type: mean_conv, " + options + "}", t.dims);
    const auto& o = std::dynamic_pointer_cast<MeanConv>(op)->options();
    const Features out = op->forward(t.features, t.graph);
    const torch::Tensor expected =
        naive_mean_conv(t.features.vertex, t.graph.edges(o.edges), *op, o.transpose, o.tanh);
    EXPECT_TRUE(torch::allclose(out.vertex, expected, 1e-10, 1e-12)) << options;
    EXPECT_EQ(out.vertex.size(1), op->out_dims().vertex);
    EXPECT_TRUE(torch::equal(out.bone, t.features.bone));
    // Vertex 7 has no edge: only its own term.
    torch::Tensor own = param(*op, "self.weight").matmul(t.features.vertex[7]) + param(*op, "self.bias");
    if (o.tanh) own = torch::tanh(own);
    EXPECT_TRUE(torch::allclose(out.vertex[7], own, 1e-12, 1e-14)) << options;
  }
}

TEST(MeanConv, TransposeIsTheAdjointOfTheNeighbourMean) {
  // With W1 = 0, W2 = I, b = 0 and no activation the layer is the neighbour mean A (or Aᵀ):
  // ⟨A x, y⟩ = ⟨x, Aᵀ y⟩ for any x, y, on the asymmetric, unsorted geodesic set too.
  const TinyGraph t = tiny_graph(3, 2);
  for (const char* set : {"one_ring", "geodesic"}) {
    std::shared_ptr<GraphOp> ops[2];
    for (int transpose = 0; transpose < 2; ++transpose) {
      ops[transpose] = make_op(std::string("{type: mean_conv, width: 3, activation: none, edges: ") +
                                   set + (transpose ? ", transpose: true}" : "}"),
                               t.dims);
      torch::NoGradGuard no_grad;
      param(*ops[transpose], "self.weight").zero_();
      param(*ops[transpose], "self.bias").zero_();
      param(*ops[transpose], "neighbours.weight").copy_(torch::eye(3, torch::kFloat64));
    }
    const torch::Tensor x = torch::randn({8, 3}, torch::kFloat64),
                        y = torch::randn({8, 3}, torch::kFloat64);
    const torch::Tensor Ax = ops[0]->forward({x, t.features.bone}, t.graph).vertex;
    const torch::Tensor ATy = ops[1]->forward({y, t.features.bone}, t.graph).vertex;
    EXPECT_NEAR((Ax * y).sum().item<double>(), (x * ATy).sum().item<double>(), 1e-12) << set;
    // The mean of a constant is that constant at every vertex with neighbours.
    const torch::Tensor ones = ops[0]->forward({torch::ones({8, 3}, torch::kFloat64), t.features.bone},
                                               t.graph).vertex;
    EXPECT_TRUE(torch::allclose(ones.slice(0, 0, 7), torch::ones({7, 3}, torch::kFloat64))) << set;
  }
}

TEST(MeanConv, EdgeOrderDoesNotMatter) {
  const TinyGraph t = tiny_graph(3, 2);
  for (const char* options : {"width: 4", "width: 4, transpose: true"}) {
    auto op = make_op(std::string("{type: mean_conv, ") + options + "}", t.dims);
    Graph shuffled = t.graph;
    shuffled.one_ring = t.graph.one_ring.flip(0).contiguous();
    EXPECT_TRUE(torch::allclose(op->forward(t.features, t.graph).vertex,
                                op->forward(t.features, shuffled).vertex, 1e-12, 1e-14))
        << options;
  }
}

TEST(MeanConv, GradientsMatchFiniteDifferences) {
  const TinyGraph t = tiny_graph(3, 2);
  for (const char* options : {"width: 4", "width: 3, transpose: true, edges: geodesic"}) {
    auto op = make_op(std::string("{type: mean_conv, ") + options + "}", t.dims);
    expect_gradients_match(*op, t.features, t.graph);
  }
}

TEST(MeanConv, WidthsAndErrors) {
  auto op = graph_op_from(config::Config::parse("{type: mean_conv, width: 64}").root());
  EXPECT_EQ(op->build({9, 0, 0}), (Dims{64, 0, 0}));
  EXPECT_EQ(op->parameters().size(), 3u);  // W1, b, W2
  expect_error<ConfigError>(
      [] { graph_op_from(config::Config::parse("{type: mean_conv}").root()); }, {"width"});
  expect_error<ConfigError>(
      [] { graph_op_from(config::Config::parse("{type: mean_conv, width: 0}").root()); },
      {"width", "≥ 1"});
  expect_error<ConfigError>(
      [] { graph_op_from(config::Config::parse("{type: mean_conv, width: 4, activation: relu}").root()); },
      {"activation", "relu", "tanh, none"});
  expect_error<ConfigError>(
      [] { graph_op_from(config::Config::parse("{type: mean_conv, width: 4, edges: skeleton}").root()); },
      {"vertex edge set"});
  const TinyGraph t = tiny_graph(3, 2);
  auto built = make_op("{type: mean_conv, width: 4}", t.dims);
  Graph bad = t.graph;
  bad.one_ring = t.graph.one_ring.clone();
  bad.one_ring[5][1] = 99;
  expect_error<c10::Error>([&] { built->forward(t.features, bad); }, {"mean_conv", "edge 5"});
  auto no_vertex = graph_op_from(config::Config::parse("{type: mean_conv, width: 4}").root());
  expect_error<c10::Error>([&] { no_vertex->build({0, 6, 3}); }, {"mean_conv", "width is 0"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::graph

namespace skinlab::graph {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using namespace skinlab::graph::testing;

TEST(MeanConv, SparseOperatorMatchesTheOp) {
  // mean_operator(edges) is the layer's A (Aᵀ): combine(x, A x) is forward(x), for the mean and
  // its transpose, on the asymmetric geodesic set as well (edges given as the one-ring here).
  const TinyGraph t = tiny_graph(3, 2, torch::kFloat32);
  for (const torch::Tensor& edges : {t.graph.one_ring, t.graph.geodesic}) {
    for (bool transpose : {false, true}) {
      MeanConv::Options o;
      o.width = 4;
      o.transpose = transpose;
      MeanConv op(o);
      op.build(t.dims);
      Graph g = t.graph;
      g.one_ring = edges;
      const torch::Tensor A = mean_operator(edges, g.num_vertices, transpose);
      const torch::Tensor expected = op.forward(t.features, g).vertex;
      const torch::Tensor got = op.combine(t.features.vertex, torch::mm(A, t.features.vertex));
      EXPECT_TRUE(torch::allclose(got, expected, 1e-6, 1e-6)) << transpose;
    }
  }
  EXPECT_THROW(mean_operator(edge_tensor({{0, 9}}), 8, false), c10::Error);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::graph

// NeuroSkinning's graph convolution unit (graph/gconv_pool.hpp) against a naive loop over
// vertices and their closed neighbourhoods: mean-then-MLP, max pooling, the skip concatenation,
// an isolated vertex, an unsorted asymmetric edge set with a self-edge, gradients, widths and
// option errors.

#include <gtest/gtest.h>

#include <set>

#include "framework/core/error.hpp"
#include "framework/graph/gconv_pool.hpp"
#include "tests/graph/graph_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::graph {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using namespace skinlab::graph::testing;

/// x_i ‖ h_i ‖ p_i with h_i = MLP(mean of x over {i} ∪ N(i)), p_i = max of h over the same set;
/// N(i) as a set, so a repeated or self edge counts once in the max (it does count in the mean:
/// the op averages over the listed rows, which for the dataset's edge lists are a set).
torch::Tensor naive_gconv_pool(const torch::Tensor& x, const torch::Tensor& edges, MlpImpl& mlp) {
  const int64_t n = x.size(0);
  std::vector<std::vector<int64_t>> rows(n);
  for (int64_t e = 0; e < edges.size(0); ++e) {
    rows[edges[e][0].item<int64_t>()].push_back(edges[e][1].item<int64_t>());
  }
  std::vector<torch::Tensor> h;
  for (int64_t i = 0; i < n; ++i) {
    torch::Tensor sum = x[i].clone();
    for (int64_t j : rows[i]) sum = sum + x[j];
    h.push_back(apply_row(mlp, sum / static_cast<double>(rows[i].size() + 1)));
  }
  std::vector<torch::Tensor> out;
  for (int64_t i = 0; i < n; ++i) {
    torch::Tensor best = h[i];
    for (int64_t j : rows[i]) best = torch::maximum(best, h[j]);
    out.push_back(torch::cat({x[i], h[i], best}));
  }
  return torch::stack(out);
}

TEST(GconvPool, MatchesLoopReference) {
  const TinyGraph t = tiny_graph(3, 2);
  for (const std::string options : {"mlp: [4]", "mlp: [4, 5]", "edges: geodesic, mlp: [3]"}) {
    auto op = make_op("{type: gconv_pool, " + options + "}", t.dims);
    const EdgeSet set = std::dynamic_pointer_cast<GconvPool>(op)->options().edges;
    const Features out = op->forward(t.features, t.graph);
    const torch::Tensor expected =
        naive_gconv_pool(t.features.vertex, t.graph.edges(set), mlp_of(*op, "mlp"));
    EXPECT_TRUE(torch::allclose(out.vertex, expected, 1e-10, 1e-12)) << options;
    EXPECT_EQ(out.vertex.size(1), op->out_dims().vertex);
    EXPECT_TRUE(torch::equal(out.bone, t.features.bone));
    // vertex 7 has no edge: h = MLP(x_7), pooled over itself only
    const torch::Tensor own = apply_row(mlp_of(*op, "mlp"), t.features.vertex[7]);
    const int64_t fh = own.size(0);
    EXPECT_TRUE(torch::allclose(out.vertex[7].slice(0, 3, 3 + fh), own));
    EXPECT_TRUE(torch::allclose(out.vertex[7].slice(0, 3 + fh), own));
  }
}

TEST(GconvPool, EdgeOrderDoesNotMatter) {
  const TinyGraph t = tiny_graph(3, 2);
  auto op = make_op("{type: gconv_pool, mlp: [4]}", t.dims);
  Graph shuffled = t.graph;
  shuffled.one_ring = t.graph.one_ring.flip(0).contiguous();
  EXPECT_TRUE(torch::allclose(op->forward(t.features, t.graph).vertex,
                              op->forward(t.features, shuffled).vertex, 1e-12, 1e-14));
}

TEST(GconvPool, GradientsMatchFiniteDifferences) {
  const TinyGraph t = tiny_graph(3, 2);
  auto op = make_op("{type: gconv_pool, mlp: [4, 3]}", t.dims);
  expect_gradients_match(*op, t.features, t.graph);
}

// NeuroSkinning Fig. 3: 64 → 576 → 832 → 1088 with F_h = 256, 128, 128.
TEST(GconvPool, WidthsFollowNeuroSkinningsFigure) {
  Dims d{64, 6, 3};
  for (auto [fh, expected] :
       std::vector<std::pair<int, int64_t>>{{256, 576}, {128, 832}, {128, 1088}}) {
    auto op = graph_op_from(
        config::Config::parse("{type: gconv_pool, mlp: [" + std::to_string(fh) + "]}").root());
    d = op->build(d);
    EXPECT_EQ(d, (Dims{expected, 6, 3}));
  }
  auto defaults = graph_op_from(config::Config::parse("{type: gconv_pool}").root());
  EXPECT_EQ(defaults->build({10, 0, 2}).vertex, 10 + 2 * 256);
  EXPECT_EQ(std::dynamic_pointer_cast<GconvPool>(defaults)->options().edges, EdgeSet::kOneRing);
}

TEST(GconvPool, ErrorsNameTheOptionOrTheEdge) {
  expect_error<ConfigError>(
      [] { graph_op_from(config::Config::parse("{type: gconv_pool, edges: skeleton}").root()); },
      {"vertex edge set"});
  expect_error<ConfigError>(
      [] { graph_op_from(config::Config::parse("{type: gconv_pool, mlp: []}").root()); }, {"mlp"});
  expect_error<ConfigError>(
      [] { graph_op_from(config::Config::parse("{type: gconv_pool, widths: [4]}").root()); },
      {"widths"});
  const TinyGraph t = tiny_graph(3, 2);
  auto op = make_op("{type: gconv_pool, mlp: [4]}", t.dims);
  Graph bad = t.graph;
  bad.one_ring = t.graph.one_ring.clone();
  bad.one_ring[5][1] = 99;
  expect_error<c10::Error>([&] { op->forward(t.features, bad); }, {"gconv_pool", "edge 5"});
  auto no_vertex = graph_op_from(config::Config::parse("{type: gconv_pool}").root());
  expect_error<c10::Error>([&] { no_vertex->build({0, 6, 3}); }, {"gconv_pool", "width is 0"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::graph

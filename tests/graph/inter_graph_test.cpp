// Inter-graph convolutions (Eq. 4 and 5) and the global branch (Fig. 3) against naive loops:
// pooling over the vertices a bone influences (with an uninfluenced bone), the ordered gather of
// the K candidates, the global max with both orders and receivers, and index errors.

#include <gtest/gtest.h>

#include "framework/graph/global_pool.hpp"
#include "framework/graph/v2b.hpp"
#include "tests/graph/graph_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::graph {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using namespace skinlab::graph::testing;

/// #B×3F [max ‖ mean ‖ scale·var] by looping over bones and their influenced vertices.
torch::Tensor naive_pool(const torch::Tensor& x, const torch::Tensor& topk, int64_t nb,
                         double scale) {
  const int64_t f = x.size(1);
  torch::Tensor out = torch::zeros({nb, 3 * f}, x.options());
  for (int64_t b = 0; b < nb; ++b) {
    std::vector<torch::Tensor> members;
    for (int64_t v = 0; v < x.size(0); ++v) {
      for (int64_t k = 0; k < topk.size(1); ++k) {
        if (topk[v][k].item<int64_t>() == b) members.push_back(x[v]);
      }
    }
    if (members.empty()) continue;
    for (int64_t c = 0; c < f; ++c) {
      double mx = -1e300, sum = 0;
      for (const auto& m : members) {
        mx = std::max(mx, m[c].item<double>());
        sum += m[c].item<double>();
      }
      const double mean = sum / members.size();
      double var = 0;
      for (const auto& m : members) var += std::pow(m[c].item<double>() - mean, 2);
      var /= members.size();
      out[b][c] = mx;
      out[b][f + c] = mean;
      out[b][2 * f + c] = scale * var;
    }
  }
  return out;
}

TEST(V2b, PoolingMatchesLoopReferenceAndEmptyBoneIsZero) {
  torch::manual_seed(2);
  const TinyGraph t = tiny_graph(3, 2);
  const torch::Tensor pooled =
      pool_vertices_to_bones(t.features.vertex, t.graph.topk_index, 5, 0.1);
  EXPECT_TRUE(torch::allclose(pooled, naive_pool(t.features.vertex, t.graph.topk_index, 5, 0.1),
                              1e-12, 1e-14));
  EXPECT_EQ(pooled[4].abs().max().item<double>(), 0.0);  // bone 4 is nobody's candidate
  // larger random case: 200 vertices, 12 bones, K = 3 distinct candidates
  const torch::Tensor x = torch::randn({200, 4}, torch::kFloat64) * 10 + 100;
  const torch::Tensor topk = torch::argsort(torch::rand({200, 12}), /*dim=*/1, /*descending=*/false)
                                 .narrow(1, 0, 3)
                                 .contiguous();
  EXPECT_TRUE(torch::allclose(pool_vertices_to_bones(x, topk, 12, 0.1),
                              naive_pool(x, topk, 12, 0.1), 1e-10, 1e-10));
}

TEST(V2b, MatchesLoopReference) {
  const TinyGraph t = tiny_graph(3, 2);
  for (const std::string options : {"mlp: [4]", "mlp: [4, 3], variance_scale: 1", "mlp: []"}) {
    auto op = make_op("{type: v2b, " + options + "}", t.dims);
    const double scale = std::dynamic_pointer_cast<V2b>(op)->options().variance_scale;
    const torch::Tensor pooled = naive_pool(t.features.vertex, t.graph.topk_index, 5, scale);
    MlpImpl& mlp = mlp_of(*op, "mlp");
    std::vector<torch::Tensor> rows;
    for (int64_t b = 0; b < 5; ++b) {
      rows.push_back(apply_row(mlp, torch::cat({t.features.bone[b], pooled[b]})));
    }
    const Features out = op->forward(t.features, t.graph);
    EXPECT_TRUE(torch::allclose(out.bone, torch::stack(rows), 1e-10, 1e-12)) << options;
    EXPECT_TRUE(torch::equal(out.vertex, t.features.vertex));
    EXPECT_EQ(out.bone.size(1), op->out_dims().bone);
  }
  EXPECT_EQ(make_op("{type: v2b, mlp: []}", t.dims)->out_dims().bone, 2 + 3 * 3);
}

TEST(V2b, PoolingWithoutGradientsGivesTheSameValues) {
  // Prediction's single-pass kernel against the differentiable form, on a random #V×K index
  // with bones no vertex picks, in both float types: equal, since the sums run in one order.
  torch::manual_seed(5);
  const int64_t nv = 200, nb = 30, k = 3;
  const torch::Tensor index = torch::randint(0, nb - 4, {nv, k}, torch::kInt64);
  for (torch::ScalarType dtype : {torch::kFloat32, torch::kFloat64}) {
    const torch::Tensor x = torch::randn({nv, 70}, dtype).requires_grad_(true);
    const torch::Tensor tracked = pool_vertices_to_bones(x, index, nb, 0.5);
    ASSERT_TRUE(tracked.requires_grad());
    torch::NoGradGuard no_grad;
    const torch::Tensor fast = pool_vertices_to_bones(x, index, nb, 0.5);
    EXPECT_TRUE(torch::equal(fast, tracked)) << (fast - tracked).abs().max().item<double>();
    EXPECT_EQ(fast.slice(0, nb - 4).abs().max().item<double>(), 0.0);  // unpicked bones
  }
}

TEST(V2b, NoGradientThroughAnUninfluencedBoneAndTopkErrors) {
  TinyGraph t = tiny_graph(3, 2);
  auto op = make_op("{type: v2b, mlp: [4]}", t.dims);
  Features in = t.features;
  in.vertex = in.vertex.clone().requires_grad_(true);
  op->forward(in, t.graph).bone[4].sum().backward();
  EXPECT_EQ(in.vertex.grad().abs().max().item<double>(), 0.0);
  t.graph.topk_index = t.graph.topk_index.clone();
  t.graph.topk_index[3][1] = -2;
  expect_error<c10::Error>([&] { op->forward(t.features, t.graph); },
                           {"v2b: topk_index[3, 1] = -2 (candidate 1 of vertex 3) is not a bone"});
  t.graph.topk_index = torch::zeros({8, 3}, torch::kInt64);
  expect_error<c10::Error>([&] { op->forward(t.features, t.graph); },
                           {"v2b: topk_index has K = 3", "built for K = 2"});
}

TEST(B2v, MatchesLoopReferenceInCandidateOrder) {
  const TinyGraph t = tiny_graph(3, 2);
  for (const std::string options : {"mlp: [4]", "mlp: [5, 3]", "mlp: []"}) {
    auto op = make_op("{type: b2v, " + options + "}", t.dims);
    MlpImpl& mlp = mlp_of(*op, "mlp");
    std::vector<torch::Tensor> rows;
    for (int64_t v = 0; v < 8; ++v) {
      std::vector<torch::Tensor> parts{t.features.vertex[v]};
      for (int64_t k = 0; k < 2; ++k) {
        parts.push_back(t.features.bone[t.graph.topk_index[v][k].item<int64_t>()]);
      }
      rows.push_back(apply_row(mlp, torch::cat(parts)));
    }
    const Features out = op->forward(t.features, t.graph);
    EXPECT_TRUE(torch::allclose(out.vertex, torch::stack(rows), 1e-10, 1e-12)) << options;
    EXPECT_TRUE(torch::equal(out.bone, t.features.bone));
    // without gradients too (Mlp::forward_gathered splits layer 0 by weight blocks either way)
    torch::NoGradGuard no_grad;
    EXPECT_TRUE(torch::allclose(op->forward(t.features, t.graph).vertex, torch::stack(rows),
                                1e-10, 1e-12))
        << options;
  }
  // without an MLP: vertex 1 (candidates 1, 0) is [f_v1 ‖ f_b1 ‖ f_b0]
  auto cat = make_op("{type: b2v, mlp: []}", t.dims);
  EXPECT_TRUE(
      torch::equal(cat->forward(t.features, t.graph).vertex[1],
                   torch::cat({t.features.vertex[1], t.features.bone[1], t.features.bone[0]})));
}

TEST(Mlp, ForwardGatheredIsTheMlpOfTheConcatenation) {
  torch::manual_seed(3);
  const int64_t nv = 9, nb = 4, k = 3;
  const torch::Tensor own = torch::randn({nv, 5}, torch::kFloat64);
  const torch::Tensor table = torch::randn({nb, 2}, torch::kFloat64);
  const torch::Tensor index = torch::randint(0, nb, {nv, k}, torch::kInt64);
  const torch::Tensor shared = torch::randn({1, 4}, torch::kFloat64);
  const torch::Tensor gathered = table.index_select(0, index.reshape({-1})).view({nv, k * 2});
  for (const bool with_shared : {true, false}) {
    Mlp mlp(5 + k * 2 + (with_shared ? 4 : 0), MlpOptions{{6, 3}});
    mlp->to(torch::kFloat64);
    std::vector<torch::Tensor> parts{own, gathered};
    if (with_shared) parts.push_back(shared.expand({nv, 4}));
    const torch::Tensor expected = mlp->forward(torch::cat(parts, 1));
    const torch::Tensor s = with_shared ? shared : torch::Tensor();
    EXPECT_TRUE(torch::allclose(mlp->forward_gathered(own, table, index, s), expected, 1e-12,
                                1e-12));
    torch::NoGradGuard no_grad;
    EXPECT_TRUE(torch::allclose(mlp->forward_gathered(own, table, index, s), expected, 1e-12,
                                1e-12));
  }
  Mlp wrong(7, MlpOptions{{2}});
  wrong->to(torch::kFloat64);
  expect_error<c10::Error>([&] { wrong->forward_gathered(own, table, index, shared); },
                           {"5 + 3×2 + 4 wide", "takes 7"});
}

// Training uses the block split too: its gradients (inputs and weights) are the concatenation's.
TEST(Mlp, ForwardGatheredHasTheConcatenationsGradients) {
  torch::manual_seed(4);
  const int64_t nv = 11, nb = 5, k = 3;
  const auto leaf = [](torch::Tensor t) { return t.requires_grad_(true); };
  const torch::Tensor own = leaf(torch::randn({nv, 4}, torch::kFloat64));
  const torch::Tensor table = leaf(torch::randn({nb, 3}, torch::kFloat64));
  const torch::Tensor shared = leaf(torch::randn({1, 2}, torch::kFloat64));
  // repeated candidates, so a table row's gradient sums over several vertices and slots
  const torch::Tensor index = torch::randint(0, nb, {nv, k}, torch::kInt64);
  Mlp mlp(4 + k * 3 + 2, MlpOptions{{6, 3}});
  mlp->to(torch::kFloat64);
  const torch::Tensor upstream = torch::randn({nv, 3}, torch::kFloat64);
  const auto grads = [&](bool split) {
    torch::Tensor out =
        split ? mlp->forward_gathered(own, table, index, shared)
              : mlp->forward(torch::cat({own, table.index_select(0, index.reshape({-1})).view({nv, -1}),
                                         shared.expand({nv, 2})},
                                        1));
    std::vector<torch::Tensor> inputs{own, table, shared};
    for (const auto& p : mlp->parameters()) inputs.push_back(p);
    return torch::autograd::grad({out}, inputs, {upstream});
  };
  const auto split = grads(true), reference = grads(false);
  ASSERT_EQ(split.size(), reference.size());
  for (std::size_t i = 0; i < split.size(); ++i) {
    EXPECT_GT(reference[i].abs().max().item<double>(), 0.0) << i;
    EXPECT_TRUE(torch::allclose(split[i], reference[i], 1e-12, 1e-12)) << i;
  }
}

// No candidate blocks, only a shared row: how a branched network's head takes global_pool's
// broadcast row (models/branched_model.cpp).
TEST(Mlp, ForwardGatheredWithOnlyASharedRow) {
  torch::manual_seed(5);
  const int64_t nv = 7;
  const torch::Tensor own = torch::randn({nv, 4}, torch::kFloat64).requires_grad_(true);
  const torch::Tensor shared = torch::randn({1, 3}, torch::kFloat64).requires_grad_(true);
  Mlp mlp(7, MlpOptions{{5, 2}});
  mlp->to(torch::kFloat64);
  const torch::Tensor split =
      mlp->forward_gathered(own, torch::empty({0, 0}, torch::kFloat64),
                            torch::empty({nv, 0}, torch::kInt64), shared);
  const torch::Tensor reference = mlp->forward(torch::cat({own, shared.expand({nv, 3})}, 1));
  EXPECT_TRUE(torch::allclose(split, reference, 1e-12, 1e-12));
  const auto g1 = torch::autograd::grad({split.sum()}, {own, shared});
  const auto g2 = torch::autograd::grad({reference.sum()}, {own, shared});
  for (int i = 0; i < 2; ++i) EXPECT_TRUE(torch::allclose(g1[i], g2[i], 1e-12, 1e-12)) << i;
}

TEST(B2v, TopkErrorsNameTheVertex) {
  TinyGraph t = tiny_graph(3, 2);
  auto op = make_op("{type: b2v, mlp: [4]}", t.dims);
  t.graph.topk_index = t.graph.topk_index.clone();
  t.graph.topk_index[5][0] = 5;
  expect_error<c10::Error>([&] { op->forward(t.features, t.graph); },
                           {"b2v: topk_index[5, 0] = 5 (candidate 0 of vertex 5)", "5 bones"});
  t.graph.topk_index = torch::Tensor();
  expect_error<c10::Error>([&] { op->forward(t.features, t.graph); },
                           {"b2v: the graph has no topk_index"});
  t.graph.topk_index = torch::zeros({7, 2}, torch::kInt64);
  expect_error<c10::Error>([&] { op->forward(t.features, t.graph); },
                           {"b2v: topk_index must be #V×K = 8×K"});
}

// ---- global_pool
// -----------------------------------------------------------------------------------

/// 1×G: max over rows of MLP(row), or MLP of the max over rows, by loops.
torch::Tensor naive_global(const torch::Tensor& x, MlpImpl& mlp, bool mlp_first) {
  torch::Tensor best;
  for (int64_t r = 0; r < x.size(0); ++r) {
    const torch::Tensor row = mlp_first ? apply_row(mlp, x[r]) : x[r];
    best = best.defined() ? torch::maximum(best, row) : row;
  }
  return mlp_first ? best : apply_row(mlp, best);
}

TEST(GlobalPool, MatchesLoopReference) {
  const TinyGraph t = tiny_graph(3, 2);
  for (const std::string options :
       {"vertex_mlp: [4], bone_mlp: [3]", "vertex_mlp: [4, 2], bone_mlp: [], to: [vertex, bone]",
        "order: max_mlp, vertex_mlp: [4], bone_mlp: [3], keep_input: false",
        "pool: [bone], bone_mlp: [3], to: [bone]"}) {
    auto op = make_op("{type: global_pool, " + options + "}", t.dims);
    const auto& o = std::dynamic_pointer_cast<GlobalPool>(op)->options();
    std::vector<torch::Tensor> globals;
    for (auto node : o.pool) {
      const bool vertex = node == GlobalPool::Node::kVertex;
      globals.push_back(naive_global(vertex ? t.features.vertex : t.features.bone,
                                     mlp_of(*op, vertex ? "vertex_mlp" : "bone_mlp"), o.mlp_first));
    }
    const torch::Tensor g = torch::cat(globals);
    const Features out = op->forward(t.features, t.graph);
    const auto expect_rows = [&](const torch::Tensor& own, const torch::Tensor& got, bool to) {
      for (int64_t r = 0; r < own.size(0); ++r) {
        const torch::Tensor want = !to ? own[r] : o.keep_input ? torch::cat({own[r], g}) : g;
        EXPECT_TRUE(torch::allclose(got[r], want, 1e-10, 1e-12)) << options << " row " << r;
      }
    };
    const auto receives = [&](GlobalPool::Node n) {
      return std::find(o.to.begin(), o.to.end(), n) != o.to.end();
    };
    expect_rows(t.features.vertex, out.vertex, receives(GlobalPool::Node::kVertex));
    expect_rows(t.features.bone, out.bone, receives(GlobalPool::Node::kBone));
    EXPECT_EQ(out.vertex.size(1), op->out_dims().vertex) << options;
    EXPECT_EQ(out.bone.size(1), op->out_dims().bone) << options;
  }
}

TEST(GlobalPool, DefaultsAndGradientsOfTheLiteralOrder) {
  auto op = graph_op_from(config::Config::parse("{type: global_pool}").root());
  EXPECT_EQ(op->build({256, 128, 3}), (Dims{256 + 1024, 128, 3}));
  const TinyGraph t = tiny_graph(3, 2);
  auto literal = make_op(
      "{type: global_pool, order: max_mlp, vertex_mlp: [3], bone_mlp: [2], "
      "keep_input: false, to: [vertex, bone]}",
      t.dims);
  expect_gradients_match(*literal, t.features, t.graph);
  expect_error<c10::Error>(
      [&] {
        make_op("{type: global_pool}", Dims{3, 0, 2});
      },
      {"global_pool: pools bone features, but their input width is 0"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::graph

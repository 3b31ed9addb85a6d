// The graph-op framework: the Graph and its checks, skeleton edges, the MLP builder, edge
// dropout, Sequence, and a suite run over every registered graph op (shapes, gradients in double
// precision by finite differences, determinism, float32, life-cycle and argument errors).

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "framework/graph/edge_dropout.hpp"
#include "tests/graph/graph_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::graph {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using namespace skinlab::graph::testing;

// ---- skeleton edges
// ------------------------------------------------------------------------------

TEST(SkeletonEdges, BonesSharingAJointBothDirectionsSorted) {
  // bones 0:(0,1) 1:(1,2) 2:(1,3) 3:(2,2) helper 4:(3,3) helper
  const torch::Tensor expected =
      edge_tensor({{0, 1}, {0, 2}, {1, 0}, {1, 2}, {1, 3}, {2, 0}, {2, 1}, {2, 4}, {3, 1}, {4, 2}});
  EXPECT_TRUE(torch::equal(skeleton_edges(tiny_bone_joints()), expected));
}

TEST(SkeletonEdges, MatchesPairwiseLoopOnRandomTrees) {
  torch::manual_seed(3);
  for (int trial = 0; trial < 5; ++trial) {
    // random tree of 20 joints: parent of j is a random earlier joint; helper bones at leaves
    std::vector<std::pair<int64_t, int64_t>> bones;
    std::vector<int> children(20, 0);
    for (int64_t j = 1; j < 20; ++j) {
      const int64_t parent = torch::randint(0, j, {1}).item<int64_t>();
      bones.push_back({parent, j});
      ++children[parent];
    }
    for (int64_t j = 1; j < 20; ++j) {
      if (children[j] == 0) bones.push_back({j, j});
    }
    const torch::Tensor joints = edge_tensor(bones);
    std::vector<std::pair<int64_t, int64_t>> naive;
    for (std::size_t a = 0; a < bones.size(); ++a) {
      for (std::size_t b = 0; b < bones.size(); ++b) {
        const auto [s1, e1] = bones[a];
        const auto [s2, e2] = bones[b];
        if (a != b && (s1 == s2 || s1 == e2 || e1 == s2 || e1 == e2)) {
          naive.push_back({static_cast<int64_t>(a), static_cast<int64_t>(b)});
        }
      }
    }
    EXPECT_TRUE(torch::equal(skeleton_edges(joints), edge_tensor(naive))) << "trial " << trial;
  }
}

TEST(SkeletonEdges, OneBoneHasNoEdgesAndBadInputIsAnError) {
  EXPECT_EQ(skeleton_edges(edge_tensor({{0, 0}})).sizes(), (std::vector<int64_t>{0, 2}));
  EXPECT_THROW(skeleton_edges(torch::zeros({3, 3}, torch::kInt64)), c10::Error);
  EXPECT_THROW(skeleton_edges(torch::zeros({3, 2}, torch::kFloat32)), c10::Error);
}

// ---- Graph
// ---------------------------------------------------------------------------------------

TEST(Graph, MakeGraphFromCharacterTensors) {
  data::CharacterTensors c;
  c.name = "tiny";
  const TinyGraph t = tiny_graph();
  c.positions = torch::zeros({8, 3});
  c.bones = torch::zeros({5, 6});
  c.bone_joints = tiny_bone_joints();
  c.one_ring = t.graph.one_ring;
  c.geodesic = t.graph.geodesic;
  c.topk_index = t.graph.topk_index;
  const Graph g = make_graph(c);
  EXPECT_EQ(g.num_vertices, 8);
  EXPECT_EQ(g.num_bones, 5);
  EXPECT_EQ(g.top_k(), 2);
  EXPECT_TRUE(torch::equal(g.skeleton, t.graph.skeleton));
  c.topk_index = c.topk_index.clone();
  c.topk_index[6][1] = 9;
  expect_error<c10::Error>([&] { make_graph(c); },
                           {"character 'tiny'", "topk_index[6, 1] = 9", "vertex 6", "5 bones"});
}

TEST(Graph, CheckEdgesNamesTheEdge) {
  TinyGraph t = tiny_graph();
  t.graph.geodesic[4][1] = 12;
  expect_error<c10::Error>([&] { t.graph.validate("op"); },
                           {"op: geodesic edge 4 is (1, 12)", "8 vertices", "0..7"});
  t.graph.geodesic[4][1] = -1;
  expect_error<c10::Error>([&] { t.graph.validate("op"); }, {"geodesic edge 4 is (1, -1)"});
  t = tiny_graph();
  t.graph.one_ring = t.graph.one_ring.to(torch::kInt32);
  expect_error<c10::Error>([&] { t.graph.validate("op"); }, {"one_ring edges must be int64"});
  t.graph.one_ring = torch::zeros({4, 3}, torch::kInt64);
  expect_error<c10::Error>([&] { t.graph.validate("op"); }, {"one_ring edges must be #E×2"});
}

// ---- MLP
// -----------------------------------------------------------------------------------------

TEST(Mlp, KaimingNormalLeakyReluGainZeroBias) {
  torch::manual_seed(0);
  Mlp mlp(1000, MlpOptions{{500, 3}});
  const torch::Tensor w = mlp->linear(0)->weight;
  const double expected_std = std::sqrt(2.0 / (1 + kLeakySlope * kLeakySlope) / 1000);
  EXPECT_NEAR(w.std().item<double>(), expected_std, 0.02 * expected_std);
  EXPECT_NEAR(w.mean().item<double>(), 0.0, 0.02 * expected_std);
  EXPECT_EQ(mlp->linear(0)->bias.abs().max().item<double>(), 0.0);
  EXPECT_EQ(mlp->out_width(), 3);
  const auto names = mlp->named_parameters().keys();
  EXPECT_EQ(names, (std::vector<std::string>{"linear0.weight", "linear0.bias", "linear1.weight",
                                             "linear1.bias"}));
}

TEST(Mlp, ActivationsDropoutAndIdentity) {
  torch::manual_seed(1);
  const torch::Tensor x = torch::randn({64, 4});
  Mlp activated(4, MlpOptions{{8, 8}});
  Mlp logits(4, MlpOptions{{8, 8}, /*activate_last=*/false});
  {
    torch::NoGradGuard g;
    logits->linear(0)->weight.copy_(activated->linear(0)->weight);
    logits->linear(1)->weight.copy_(activated->linear(1)->weight);
  }
  const torch::Tensor y = logits->forward(x);
  EXPECT_TRUE(torch::allclose(activated->forward(x), torch::leaky_relu(y, 0.2)));
  EXPECT_LT(y.min().item<double>(), 0.0);
  // dropout only in training mode, never in front of the first layer
  Mlp dropped(4, MlpOptions{{8, 8}, true, 0.5});
  dropped->eval();
  EXPECT_TRUE(torch::equal(dropped->forward(x), dropped->forward(x)));
  dropped->train();
  EXPECT_FALSE(torch::equal(dropped->forward(x), dropped->forward(x)));
  Mlp identity(4, MlpOptions{});
  EXPECT_TRUE(torch::equal(identity->forward(x), x));
  EXPECT_EQ(identity->out_width(), 4);
  EXPECT_THROW(Mlp(4, MlpOptions{{0}}), c10::Error);
  EXPECT_THROW(Mlp(4, MlpOptions{{3}, true, 1.0}), c10::Error);
  EXPECT_THROW(activated->forward(torch::randn({2, 5})), c10::Error);
}

// ---- edge dropout
// --------------------------------------------------------------------------------

torch::Tensor symmetric_random_edges(int64_t n, int64_t m) {
  const torch::Tensor a = torch::randint(0, n, {m}, torch::kInt64);
  const torch::Tensor b = torch::randint(0, n, {m}, torch::kInt64);
  return torch::cat({torch::stack({a, b}, 1), torch::stack({b, a}, 1)});
}

TEST(EdgeDropout, DropsEightyFivePercentInOrder) {
  torch::manual_seed(5);
  const torch::Tensor edges = symmetric_random_edges(5000, 50000);
  const torch::Tensor kept = drop_edges(edges, 0.85);
  EXPECT_NEAR(static_cast<double>(kept.size(0)) / edges.size(0), 0.15, 0.01);
  // a subsequence: the kept rows appear in the original order
  const torch::Tensor key = edges.select(1, 0) * 5000 + edges.select(1, 1);
  const torch::Tensor kept_key = kept.select(1, 0) * 5000 + kept.select(1, 1);
  int64_t pos = 0;
  bool subsequence = true;
  for (int64_t r = 0; r < kept_key.size(0) && subsequence; ++r) {
    const int64_t k = kept_key[r].item<int64_t>();
    while (pos < key.size(0) && key[pos].item<int64_t>() != k) ++pos;
    subsequence = pos < key.size(0);
    ++pos;
  }
  EXPECT_TRUE(subsequence);
  EXPECT_TRUE(torch::equal(drop_edges(edges, 0.0), edges));
  EXPECT_EQ(drop_edges(edges, 1.0).size(0), 0);
  torch::manual_seed(11);
  const torch::Tensor first = drop_edges(edges, 0.5);
  torch::manual_seed(11);
  EXPECT_TRUE(torch::equal(drop_edges(edges, 0.5), first));
  EXPECT_THROW(drop_edges(edges, 1.5), c10::Error);
}

TEST(EdgeDropout, SymmetricKeepsBothDirectionsTogether) {
  torch::manual_seed(6);
  const torch::Tensor edges = symmetric_random_edges(300, 2000);
  const torch::Tensor kept = drop_edges(edges, 0.85, /*symmetric=*/true);
  std::set<std::pair<int64_t, int64_t>> in;
  for (int64_t r = 0; r < kept.size(0); ++r) {
    in.insert({kept[r][0].item<int64_t>(), kept[r][1].item<int64_t>()});
  }
  for (const auto& [i, j] : in) EXPECT_TRUE(in.count({j, i})) << i << " " << j;
  EXPECT_NEAR(static_cast<double>(kept.size(0)) / edges.size(0), 0.15, 0.03);
}

TEST(EdgeDropout, GraphLevelOptionsFromConfig) {
  const auto config = config::Config::parse(
      "a: {p: 1.0, edges: [geodesic]}\nb: {p: 2}\nc: {edges: [one_ring, one_ring]}\n"
      "d: {edges: [mesh]}\ne: {q: 1}\n",
      "test.yaml");
  const auto o = EdgeDropoutOptions::from(config.root()["a"]);
  const TinyGraph t = tiny_graph();
  const Graph g = drop_edges(t.graph, o);
  EXPECT_EQ(g.geodesic.size(0), 0);
  EXPECT_TRUE(torch::equal(g.one_ring, t.graph.one_ring));
  const auto defaults = EdgeDropoutOptions::from(config.root()["missing"]);
  EXPECT_EQ(defaults.p, 0.85);
  EXPECT_EQ(defaults.edges.size(), 2u);
  expect_error<ConfigError>([&] { EdgeDropoutOptions::from(config.root()["b"]); },
                            {"test.yaml:2: b.p", "[0, 1]"});
  expect_error<ConfigError>([&] { EdgeDropoutOptions::from(config.root()["c"]); },
                            {"listed twice"});
  expect_error<ConfigError>([&] { EdgeDropoutOptions::from(config.root()["d"]); },
                            {"unknown edge set 'mesh'", "one_ring, geodesic, skeleton"});
  expect_error<ConfigError>([&] { EdgeDropoutOptions::from(config.root()["e"]); },
                            {"unknown field"});
}

// ---- Sequence
// --------------------------------------------------------------------------------------

TEST(Sequence, BuildsFromAConfigListAndChainsWidths) {
  const auto config = config::Config::parse(
      "ops:\n"
      "  - {type: b2v, mlp: [6]}\n"
      "  - {type: v2b, mlp: [5]}\n"
      "  - {type: mesh_conv, edge_mlp: [4], mlp: [7]}\n"
      "  - {type: edge_conv, edges: skeleton, mlp: [3]}\n",
      "test.yaml");
  auto seq = Sequence::from(config.root()["ops"]);
  const Dims out = seq->build({3, 2, 2});
  EXPECT_EQ(out, (Dims{7, 3, 2}));
  seq->to(torch::kFloat64);
  std::vector<std::string> names;
  for (const auto& c : seq->named_children()) names.push_back(c.key());
  EXPECT_EQ(names, (std::vector<std::string>{"0_b2v", "1_v2b", "2_mesh_conv", "3_edge_conv"}));
  EXPECT_TRUE(seq->named_parameters().contains("2_mesh_conv.edge_mlp_geodesic.linear0.weight"));
  const TinyGraph t = tiny_graph();
  Features manual = t.features;
  for (const auto& op : seq->ops()) manual = op->forward(manual, t.graph);
  const Features result = seq->forward(t.features, t.graph);
  EXPECT_TRUE(torch::equal(result.vertex, manual.vertex));
  EXPECT_TRUE(torch::equal(result.bone, manual.bone));
  EXPECT_EQ(result.vertex.sizes(), (std::vector<int64_t>{8, 7}));
  // an empty list is the identity
  auto empty = Sequence::from(config.root()["none"]);
  EXPECT_EQ(empty->build({3, 2, 2}), (Dims{3, 2, 2}));
  EXPECT_TRUE(torch::equal(empty->forward(t.features, t.graph).vertex, t.features.vertex));
}

TEST(Sequence, ConfigErrorsNameTheEntry) {
  const auto config = config::Config::parse(
      "a:\n  - {type: b2v}\n  - {type: spectral_conv}\n"
      "b:\n  - {type: edge_conv, edges: skeleton, mlp: [4], self_loop: false}\n"
      "c:\n  - {type: edge_conv, edges: bones, mlp: [4]}\n"
      "d:\n  - {type: edge_conv, edges: skeleton, mlp: []}\n"
      "e:\n  - {type: edge_conv, mlp: [4]}\n"
      "f: {type: b2v}\n"
      "g:\n  - {type: mesh_conv, edges: [one_ring, skeleton]}\n"
      "h:\n  - {type: global_pool, order: max_first}\n"
      "i:\n  - {type: v2b, variance_scale: -1}\n",
      "test.yaml");
  const auto root = config.root();
  expect_error<RegistryError>(
      [&] { Sequence::from(root["a"]); },
      {"test.yaml:3: a[1]", "unknown graph_op type 'spectral_conv'",
       "b2v, edge_conv, gat_block, gconv_pool, global_pool, mean_conv, mesh_conv, v2b"});
  expect_error<ConfigError>(
      [&] { Sequence::from(root["b"]); },
      {"test.yaml:5", "unknown field of graph_op 'edge_conv'", "did you mean 'self_loops'?"});
  expect_error<ConfigError>([&] { Sequence::from(root["c"]); },
                            {"c[0].edges", "unknown edge set 'bones'"});
  expect_error<ConfigError>([&] { Sequence::from(root["d"]); }, {"d[0].mlp", "at least one layer"});
  expect_error<ConfigError>([&] { Sequence::from(root["e"]); }, {"missing required field 'edges'"});
  expect_error<ConfigError>([&] { Sequence::from(root["f"]); }, {"expected a list of graph ops"});
  expect_error<ConfigError>([&] { Sequence::from(root["g"]); },
                            {"g[0].edges[1]", "vertex edge sets"});
  expect_error<ConfigError>([&] { Sequence::from(root["h"]); }, {"h[0].order", "mlp_max"});
  expect_error<ConfigError>([&] { Sequence::from(root["i"]); }, {"i[0].variance_scale", "≥ 0"});
}

TEST(Sequence, BuildErrorsNameTheOp) {
  const auto config = config::Config::parse("ops: [{type: v2b}]");
  auto seq = Sequence::from(config.root()["ops"]);
  expect_error<c10::Error>(
      [&] {
        seq->build({3, 0, 2});
      },
      {"v2b: needs vertex and bone features", "bone 0"});
  auto b2v = graph_op_from(config::Config::parse("{type: b2v}").root());
  expect_error<c10::Error>([&] { b2v->build({3, 2, 0}); }, {"b2v: needs K ≥ 1"});
}

// ---- every registered op
// ---------------------------------------------------------------------------

/// A small config of every registered op (tiny widths; multi-layer MLPs where the op has one).
const std::map<std::string, std::string>& op_configs() {
  static const std::map<std::string, std::string> configs = {
      {"edge_conv", "{type: edge_conv, edges: geodesic, mlp: [4, 3]}"},
      {"mesh_conv", "{type: mesh_conv, edge_mlp: [4], mlp: [3]}"},
      {"v2b", "{type: v2b, mlp: [4, 3]}"},
      {"b2v", "{type: b2v, mlp: [4, 3]}"},
      {"global_pool", "{type: global_pool, vertex_mlp: [3], bone_mlp: [2], to: [vertex, bone]}"},
      {"gconv_pool", "{type: gconv_pool, mlp: [4, 3]}"},
      {"gat_block", "{type: gat_block, heads: 2, hidden: 2, beta: 0.5}"},
      {"mean_conv", "{type: mean_conv, width: 3, transpose: true}"},
  };
  return configs;
}

TEST(GraphOps, EveryRegisteredOpHasATestConfig) {
  std::vector<std::string> tested;
  for (const auto& [key, yaml] : op_configs()) tested.push_back(key);
  EXPECT_EQ(graph_op_registry().keys(), tested);
}

class EveryOp : public ::testing::TestWithParam<std::string> {
 protected:
  std::shared_ptr<GraphOp> make(torch::ScalarType dtype = torch::kFloat64) {
    return make_op(op_configs().at(GetParam()), tiny_graph().dims, dtype);
  }
};

TEST_P(EveryOp, OutputShapesMatchBuiltWidths) {
  auto op = make();
  const TinyGraph t = tiny_graph();
  const Features out = op->forward(t.features, t.graph);
  EXPECT_EQ(op->type(), GetParam());
  EXPECT_EQ(op->out_dims().top_k, 2);
  EXPECT_EQ(out.vertex.sizes(), (std::vector<int64_t>{8, op->out_dims().vertex}));
  EXPECT_EQ(out.bone.sizes(), (std::vector<int64_t>{5, op->out_dims().bone}));
  EXPECT_TRUE(torch::isfinite(out.vertex).all().item<bool>());
  EXPECT_TRUE(torch::isfinite(out.bone).all().item<bool>());
  EXPECT_FALSE(op->parameters().empty());
}

TEST_P(EveryOp, GradientsMatchFiniteDifferences) {
  auto op = make();
  const TinyGraph t = tiny_graph();
  expect_gradients_match(*op, t.features, t.graph);
}

TEST_P(EveryOp, DeterministicAndRunsInFloat32) {
  auto op = make(torch::kFloat32);
  const TinyGraph t = tiny_graph(3, 2, torch::kFloat32);
  const Features a = op->forward(t.features, t.graph), b = op->forward(t.features, t.graph);
  EXPECT_TRUE(torch::equal(a.vertex, b.vertex));
  EXPECT_TRUE(torch::equal(a.bone, b.bone));
  EXPECT_EQ(a.vertex.scalar_type(), torch::kFloat32);
}

TEST_P(EveryOp, LifeCycleAndFeatureErrors) {
  const TinyGraph t = tiny_graph();
  auto unbuilt = graph_op_from(config::Config::parse(op_configs().at(GetParam())).root());
  expect_error<c10::Error>([&] { unbuilt->forward(t.features, t.graph); },
                           {GetParam() + ": forward() before build()"});
  auto op = make();
  expect_error<c10::Error>([&] { op->build(t.dims); }, {GetParam() + ": build() called twice"});
  // features of the wrong width or row count, or missing
  Features wide = t.features;
  wide.vertex = torch::randn({8, 4}, torch::kFloat64);
  wide.bone = torch::randn({5, 3}, torch::kFloat64);
  expect_error<c10::Error>([&] { op->forward(wide, t.graph); },
                           {GetParam() + ": ", "have width", "built for width"});
  Features rows = t.features;
  rows.vertex = torch::randn({7, 3}, torch::kFloat64);
  rows.bone = torch::randn({4, 2}, torch::kFloat64);
  expect_error<c10::Error>([&] { op->forward(rows, t.graph); },
                           {GetParam() + ": ", "rows, but the graph has"});
  expect_error<c10::Error>([&] { op->forward(Features{}, t.graph); },
                           {GetParam() + ": needs", "got none"});
  Features flat = t.features;
  flat.vertex = flat.vertex.view(-1);
  flat.bone = flat.bone.view(-1);
  expect_error<c10::Error>([&] { op->forward(flat, t.graph); }, {"must be a 2-D"});
}

INSTANTIATE_TEST_SUITE_P(GraphOps, EveryOp,
                         ::testing::Values("b2v", "edge_conv", "gat_block", "global_pool",
                                           "mean_conv", "mesh_conv", "v2b"),
                         [](const auto& info) { return info.param; });

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::graph

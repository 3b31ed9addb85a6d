// Intra-graph convolutions (Eq. 2 and 3) against naive loops over nodes and neighbours: every
// edge set, one- and multi-layer MLPs (the two code paths of edge_conv_max), with and without
// self-loops, nodes without neighbours, and index errors that name the edge.

#include <gtest/gtest.h>

#include "framework/graph/aggregate.hpp"
#include "framework/graph/mesh_conv.hpp"
#include "tests/graph/graph_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::graph {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using namespace skinlab::graph::testing;

struct EdgeConvCase {
  std::string set;
  std::string mlp;
  bool self_loops;
};
void PrintTo(const EdgeConvCase& c, std::ostream* os) {
  *os << c.set << " mlp " << c.mlp << (c.self_loops ? " self-loops" : " no self-loops");
}

class EdgeConvVsNaive : public ::testing::TestWithParam<EdgeConvCase> {};

std::shared_ptr<GraphOp> make_case_op(const EdgeConvCase& c, const Dims& dims) {
  return make_op("{type: edge_conv, edges: " + c.set + ", mlp: " + c.mlp +
                     ", self_loops: " + (c.self_loops ? "true" : "false") + "}",
                 dims);
}

TEST_P(EdgeConvVsNaive, MatchesLoopReference) {
  const auto& c = GetParam();
  const TinyGraph t = tiny_graph(3, 2);
  auto op = make_case_op(c, t.dims);
  const Features out = op->forward(t.features, t.graph);
  const bool bones = c.set == "skeleton";
  const torch::Tensor& x = bones ? t.features.bone : t.features.vertex;
  const EdgeSet set =
      bones ? EdgeSet::kSkeleton : (c.set == "one_ring" ? EdgeSet::kOneRing : EdgeSet::kGeodesic);
  const torch::Tensor expected =
      naive_edge_conv(x, t.graph.edges(set), mlp_of(*op, "mlp"), c.self_loops);
  EXPECT_TRUE(torch::allclose(bones ? out.bone : out.vertex, expected, 1e-10, 1e-12));
  // the other node type passes through untouched
  EXPECT_TRUE(
      torch::equal(bones ? out.vertex : out.bone, bones ? t.features.vertex : t.features.bone));
  // vertex 7 has no edge: MLP(f ‖ 0) with self-loops, else zero
  if (!bones) {
    const torch::Tensor isolated = out.vertex[7];
    if (c.self_loops) {
      const torch::Tensor own =
          apply_row(mlp_of(*op, "mlp"), torch::cat({x[7], torch::zeros_like(x[7])}));
      EXPECT_TRUE(torch::allclose(isolated, own));
    } else {
      EXPECT_EQ(isolated.abs().max().item<double>(), 0.0);
    }
  }
}

TEST_P(EdgeConvVsNaive, GradientsMatchFiniteDifferences) {
  const auto& c = GetParam();
  const TinyGraph t = tiny_graph(3, 2);
  auto op = make_case_op(c, t.dims);
  expect_gradients_match(*op, t.features, t.graph);
}

TEST_P(EdgeConvVsNaive, WithoutGradientsTheSameValues) {
  // Prediction and evaluation run without gradients, where a one-layer MLP takes the fused
  // gather-min kernel (gather_segment_min): a min is exact, so the values are equal, not close.
  const auto& c = GetParam();
  const TinyGraph t = tiny_graph(3, 2);
  auto op = make_case_op(c, t.dims);
  const Features trained = op->forward(t.features, t.graph);
  ASSERT_TRUE((c.set == "skeleton" ? trained.bone : trained.vertex).requires_grad());
  torch::NoGradGuard no_grad;
  const Features inferred = op->forward(t.features, t.graph);
  EXPECT_TRUE(torch::equal(inferred.vertex, trained.vertex));
  EXPECT_TRUE(torch::equal(inferred.bone, trained.bone));
}

INSTANTIATE_TEST_SUITE_P(EdgeConv, EdgeConvVsNaive,
                         ::testing::Values(EdgeConvCase{"one_ring", "[5]", true},
                                           EdgeConvCase{"one_ring", "[5, 4]", true},
                                           EdgeConvCase{"geodesic", "[5]", true},
                                           EdgeConvCase{"geodesic", "[4, 3, 2]", false},
                                           EdgeConvCase{"geodesic", "[5]", false},
                                           EdgeConvCase{"skeleton", "[4]", true},
                                           EdgeConvCase{"skeleton", "[4, 4]", false}),
                         [](const auto& info) {
                           return info.param.set + "_" + std::to_string(info.index) +
                                  (info.param.self_loops ? "_self" : "_noself");
                         });

TEST(EdgeConv, LargerRandomGraphMatchesNaive) {
  torch::manual_seed(4);
  const int64_t n = 60;
  Graph g;
  g.num_vertices = n;
  g.num_bones = 1;
  g.geodesic = torch::randint(0, n, {400, 2}, torch::kInt64);
  g.topk_index = torch::zeros({n, 1}, torch::kInt64);
  const torch::Tensor x = torch::randn({n, 6}, torch::kFloat64);
  for (const std::string mlp : {"[8]", "[8, 5]"}) {
    auto op = make_op("{type: edge_conv, edges: geodesic, mlp: " + mlp + "}", Dims{6, 1, 1});
    const Features out = op->forward({x, torch::zeros({1, 1}, torch::kFloat64)}, g);
    EXPECT_TRUE(torch::allclose(
        out.vertex, naive_edge_conv(x, g.geodesic, mlp_of(*op, "mlp"), true), 1e-10, 1e-12))
        << mlp;
  }
}

TEST(GatherSegmentMin, EqualsGatherThenSegmentMinAndRefusesGradients) {
  torch::manual_seed(9);
  const int64_t n = 50;
  // unsorted; nodes 40..49 get no row
  const torch::Tensor index = torch::randint(0, n - 10, {300}, torch::kInt64);
  const torch::Tensor neighbour = torch::randint(0, n, {300}, torch::kInt64);
  const Segments s = Segments::of(index, n);
  for (torch::ScalarType dtype : {torch::kFloat32, torch::kFloat64}) {
    const torch::Tensor values = torch::randn({n, 7}, dtype);
    const torch::Tensor expected = segment_extremum(
        values.index_select(0, s.sorted_index(neighbour)), s, s.sorted_index(index), "min");
    const torch::Tensor got = gather_segment_min(values, s.sorted_index(neighbour), s);
    EXPECT_TRUE(torch::equal(got, expected));
    const torch::Tensor empty = s.lengths == 0;
    ASSERT_GT(empty.sum().item<int64_t>(), 0);  // the case of a node without rows is covered
    EXPECT_TRUE(torch::isinf(got.index({empty})).all().item<bool>());
  }
  const torch::Tensor tracked = torch::randn({n, 2}, torch::requires_grad());
  expect_error<c10::Error>([&] { gather_segment_min(tracked, s.sorted_index(neighbour), s); },
                           {"no backward"});
}

TEST(EdgeConv, EdgeOrderDoesNotMatter) {
  // sorted by receiver (the dataset's layout: no sort inside) vs shuffled (sorted inside)
  TinyGraph t = tiny_graph();
  for (const std::string mlp : {"[4]", "[4, 3]"}) {
    auto op = make_op("{type: edge_conv, edges: one_ring, mlp: " + mlp + "}", t.dims);
    const torch::Tensor e = t.graph.one_ring;
    Graph sorted = t.graph, shuffled = t.graph;
    sorted.one_ring = e.index_select(0, std::get<1>(e.select(1, 0).sort(true, 0, false)));
    shuffled.one_ring = e.index_select(0, torch::randperm(e.size(0), torch::kInt64));
    const torch::Tensor reference = naive_edge_conv(t.features.vertex, e, mlp_of(*op, "mlp"), true);
    EXPECT_TRUE(torch::allclose(op->forward(t.features, sorted).vertex, reference, 1e-10, 1e-12));
    EXPECT_TRUE(torch::allclose(op->forward(t.features, shuffled).vertex, reference, 1e-10, 1e-12));
    expect_gradients_match(*op, t.features, sorted);
  }
}

TEST(EdgeConv, NoEdgesAtAll) {
  // e.g. every edge dropped: self-loops give MLP(f ‖ 0), without them every node gets 0
  TinyGraph t = tiny_graph();
  t.graph.geodesic = torch::zeros({0, 2}, torch::kInt64);
  for (const std::string mlp : {"[4]", "[4, 3]"}) {
    auto op = make_op("{type: edge_conv, edges: geodesic, mlp: " + mlp + "}", t.dims);
    EXPECT_TRUE(torch::allclose(
        op->forward(t.features, t.graph).vertex,
        naive_edge_conv(t.features.vertex, t.graph.geodesic, mlp_of(*op, "mlp"), true)));
    expect_gradients_match(*op, t.features, t.graph);
    auto bare =
        make_op("{type: edge_conv, edges: geodesic, self_loops: false, mlp: " + mlp + "}", t.dims);
    EXPECT_EQ(bare->forward(t.features, t.graph).vertex.abs().max().item<double>(), 0.0);
  }
}

TEST(EdgeConv, SelfEdgesInTheListChangeNothing) {
  TinyGraph t = tiny_graph();
  auto op = make_op("{type: edge_conv, edges: one_ring, mlp: [4, 4]}", t.dims);
  const torch::Tensor plain = op->forward(t.features, t.graph).vertex;
  t.graph.one_ring = torch::cat({t.graph.one_ring, edge_tensor({{3, 3}, {7, 7}})});
  EXPECT_TRUE(torch::allclose(op->forward(t.features, t.graph).vertex, plain));
}

TEST(EdgeConv, IndexErrorsNameTheEdge) {
  TinyGraph t = tiny_graph();
  auto op = make_op("{type: edge_conv, edges: skeleton, mlp: [4]}", t.dims);
  t.graph.skeleton = t.graph.skeleton.clone();
  t.graph.skeleton[3][0] = 5;
  expect_error<c10::Error>([&] { op->forward(t.features, t.graph); },
                           {"edge_conv: skeleton edge 3 is (5, 2), but the graph has 5 bones"});
  t.graph.skeleton = torch::Tensor();
  expect_error<c10::Error>([&] { op->forward(t.features, t.graph); },
                           {"edge_conv: the graph has no skeleton edges"});
  auto on_mesh = make_op("{type: edge_conv, edges: one_ring, mlp: [4]}", Dims{3, 0, 2});
  expect_error<c10::Error>(
      [&] {
        make_op("{type: edge_conv, edges: skeleton, mlp: [4]}", Dims{3, 0, 2});
      },
      {"edge_conv: runs on skeleton edges, so it needs bone features"});
  // vertex-only features are enough for a mesh edge set
  EXPECT_NO_THROW(on_mesh->forward({t.features.vertex, {}}, t.graph));
}

// ---- mesh_conv
// ------------------------------------------------------------------------------------

TEST(MeshConv, MatchesLoopReference) {
  const TinyGraph t = tiny_graph(3, 2);
  for (const std::string options :
       {"edge_mlp: [4], mlp: [5]", "edge_mlp: [4, 3], mlp: [5, 2]", "edge_mlp: [4], mlp: []",
        "edges: [geodesic, one_ring], edge_mlp: [4], mlp: [3], self_loops: false"}) {
    auto op = make_op("{type: mesh_conv, " + options + "}", t.dims);
    const auto& o = std::dynamic_pointer_cast<MeshConv>(op)->options();
    std::vector<torch::Tensor> branches;
    for (EdgeSet set : o.edges) {
      branches.push_back(naive_edge_conv(t.features.vertex, t.graph.edges(set),
                                         mlp_of(*op, std::string("edge_mlp_") + to_string(set)),
                                         o.self_loops));
    }
    MlpImpl& mlp = mlp_of(*op, "mlp");
    const torch::Tensor cat = torch::cat(branches, 1);
    std::vector<torch::Tensor> rows;
    for (int64_t v = 0; v < 8; ++v) rows.push_back(apply_row(mlp, cat[v]));
    const Features out = op->forward(t.features, t.graph);
    EXPECT_TRUE(torch::allclose(out.vertex, torch::stack(rows), 1e-10, 1e-12)) << options;
    EXPECT_TRUE(torch::equal(out.bone, t.features.bone));
    EXPECT_EQ(out.vertex.size(1), op->out_dims().vertex);
  }
}

TEST(MeshConv, OneBranchAblationAndGradients) {
  const TinyGraph t = tiny_graph(3, 2);
  auto op = make_op("{type: mesh_conv, edges: [one_ring], edge_mlp: [4], mlp: [3]}", t.dims);
  EXPECT_EQ(op->named_children().size(), 2u);  // edge_mlp_one_ring, mlp
  Graph no_geodesic = t.graph;
  no_geodesic.geodesic = torch::Tensor();  // not needed, not checked
  EXPECT_NO_THROW(op->forward(t.features, no_geodesic));
  expect_gradients_match(*op, t.features, t.graph);
  auto both = make_op("{type: mesh_conv, edge_mlp: [4], mlp: [3]}", t.dims);
  expect_error<c10::Error>([&] { both->forward(t.features, no_geodesic); },
                           {"mesh_conv: the graph has no geodesic edges"});
}

TEST(MeshConv, DefaultsAreThePaperWidths) {
  auto op = graph_op_from(config::Config::parse("{type: mesh_conv}").root());
  EXPECT_EQ(op->build({6, 6, 3}), (Dims{256, 6, 3}));
  const auto& o = std::dynamic_pointer_cast<MeshConv>(op)->options();
  EXPECT_EQ(o.edges, (std::vector<EdgeSet>{EdgeSet::kOneRing, EdgeSet::kGeodesic}));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::graph

// gat_block (DenseGATs Sec. 3.2, Eq. 1–4) against a naive loop over vertices, neighbours and
// heads written from the equations: every combination of heads 1/3, concat, self-loops, β 0/>0
// and each activation, on a small triangulated grid with an isolated vertex; the attention of
// every receiver sums to 1; gradients against finite differences (float64); relabelling the
// vertices permutes the output; the paper's widths; config, build and forward errors.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "framework/core/error.hpp"
#include "framework/graph/gat_block.hpp"
#include "tests/graph/graph_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::graph {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using namespace skinlab::graph::testing;

constexpr int64_t kRows = 5, kCols = 6;
constexpr int64_t kGridVertices = kRows * kCols + 1;  // + vertex 30, on no edge
constexpr int64_t kIsolated = kRows * kCols;

/// A 5×6 grid of vertices, each square split by one diagonal, both directions of every edge,
/// sorted by receiver (the dataset's layout), and vertex 30 on no edge. Features of width `d`.
TinyGraph grid(int64_t d = 4, uint64_t seed = 3) {
  torch::manual_seed(seed);
  std::vector<std::pair<int64_t, int64_t>> pairs;
  const auto id = [](int64_t r, int64_t c) { return r * kCols + c; };
  for (int64_t r = 0; r < kRows; ++r) {
    for (int64_t c = 0; c < kCols; ++c) {
      const auto link = [&](int64_t a, int64_t b) {
        pairs.push_back({a, b});
        pairs.push_back({b, a});
      };
      if (c + 1 < kCols) link(id(r, c), id(r, c + 1));
      if (r + 1 < kRows) link(id(r, c), id(r + 1, c));
      if (r + 1 < kRows && c + 1 < kCols) link(id(r, c), id(r + 1, c + 1));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  TinyGraph t;
  t.graph.num_vertices = kGridVertices;
  t.graph.num_bones = 2;
  t.graph.one_ring = edge_tensor(pairs);
  t.graph.topk_index = torch::zeros({kGridVertices, 1}, torch::kInt64);
  t.features.vertex = torch::randn({kGridVertices, d}, torch::kFloat64);
  t.features.bone = torch::randn({2, 3}, torch::kFloat64);
  t.dims = Dims{d, 3, 1};
  return t;
}

struct GatCase {
  int64_t heads = 1;
  bool concat = true;
  bool self_loops = true;
  double beta = 0;
  std::string activation = "tanhshrink";
  std::string yaml(const std::string& edges = "one_ring") const {
    return "{type: gat_block, hidden: 2, heads: " + std::to_string(heads) +
           ", concat: " + (concat ? "true" : "false") +
           ", self_loops: " + (self_loops ? "true" : "false") + ", beta: " + std::to_string(beta) +
           ", activation: " + activation + ", edges: " + edges + "}";
  }
  std::string name() const {
    return "heads" + std::to_string(heads) + (concat ? "_concat" : "_mean") +
           (self_loops ? "_self" : "_noself") + (beta > 0 ? "_beta" : "_nobeta") + "_" + activation;
  }
};
void PrintTo(const GatCase& c, std::ostream* os) { *os << c.name(); }

std::vector<GatCase> all_cases() {
  std::vector<GatCase> out;
  for (int64_t heads : {1, 3})
    for (bool concat : {true, false})
      for (bool self_loops : {true, false})
        for (double beta : {0.0, 0.5})
          for (const char* activation : {"tanhshrink", "elu", "none"})
            out.push_back({heads, concat, self_loops, beta, activation});
  return out;
}

torch::Tensor param(GraphOp& op, const std::string& name) {
  const auto params = op.named_parameters();
  const auto* p = params.find(name);
  return p ? *p : torch::Tensor();
}

struct Naive {
  torch::Tensor out;    ///< #V×width
  torch::Tensor edges;  ///< #M×2, per receiver: i itself first (self-loops), then list order
  torch::Tensor alpha;  ///< #M×K
};

/// Eq. 1–4 node by node, head by head, from the op's parameters; no max shift in the softmax.
Naive naive_gat(GraphOp& op, const GatCase& c, const torch::Tensor& x,
                const torch::Tensor& edge_list, double slope = 0.2) {
  const int64_t n = x.size(0), k = c.heads;
  const torch::Tensor w = param(op, "w.weight"), a_dst = param(op, "a_dst"),
                      a_src = param(op, "a_src"), h = param(op, "h.weight"), b = param(op, "bias");
  const int64_t f = w.size(0) / k;
  std::vector<std::vector<int64_t>> neighbours(n);
  for (int64_t i = 0; i < n; ++i) {
    if (c.self_loops) neighbours[i].push_back(i);
  }
  for (int64_t e = 0; e < edge_list.size(0); ++e) {
    const int64_t i = edge_list[e][0].item<int64_t>(), j = edge_list[e][1].item<int64_t>();
    if (!(c.self_loops && i == j)) neighbours[i].push_back(j);
  }
  std::vector<torch::Tensor> rows, alpha_rows;
  std::vector<std::pair<int64_t, int64_t>> pairs;
  for (int64_t i = 0; i < n; ++i) {
    std::vector<torch::Tensor> heads;
    std::vector<std::vector<double>> alpha(neighbours[i].size(), std::vector<double>(k));
    for (int64_t head = 0; head < k; ++head) {
      const torch::Tensor wk = w.narrow(0, head * f, f);                // W^k, F×d
      const torch::Tensor ak = torch::cat({a_dst[head], a_src[head]});  // a^k ∈ R^{2F}
      const torch::Tensor zi = wk.mv(x[i]);
      std::vector<torch::Tensor> exps, zs;
      for (int64_t j : neighbours[i]) {
        const torch::Tensor zj = wk.mv(x[j]);
        exps.push_back(torch::exp(torch::leaky_relu(ak.dot(torch::cat({zi, zj})), slope)));
        zs.push_back(zj);
      }
      torch::Tensor sum = torch::zeros({f}, x.options());
      if (!exps.empty()) {
        const torch::Tensor denominator = torch::stack(exps).sum();
        for (std::size_t q = 0; q < zs.size(); ++q) {
          const torch::Tensor a = exps[q] / denominator;
          alpha[q][head] = a.item<double>();
          sum = sum + a * zs[q];
        }
      }
      heads.push_back(sum);
    }
    torch::Tensor y = c.concat ? torch::cat(heads) : torch::stack(heads).mean(0);
    if (h.defined()) y = torch::cat({y, h.mv(x[i])});
    y = y + b;
    if (c.activation == "tanhshrink") y = y - torch::tanh(y);
    if (c.activation == "elu") y = torch::elu(y);
    rows.push_back(y);
    for (std::size_t q = 0; q < neighbours[i].size(); ++q) {
      pairs.push_back({i, neighbours[i][q]});
      alpha_rows.push_back(torch::tensor(alpha[q], torch::kFloat64));
    }
  }
  return {torch::stack(rows), edge_tensor(pairs),
          alpha_rows.empty() ? torch::zeros({0, k}, torch::kFloat64) : torch::stack(alpha_rows)};
}

std::shared_ptr<GatBlock> make_gat(const std::string& yaml, const Dims& dims,
                                   torch::ScalarType dtype = torch::kFloat64) {
  return std::dynamic_pointer_cast<GatBlock>(make_op(yaml, dims, dtype));
}

/// Every parameter moved by N(0, 0.7²): the bias starts at 0 and the attention vectors are
/// Glorot-small, so this makes the comparison see the bias and the attention far from uniform.
void perturb(GraphOp& op) {
  torch::NoGradGuard no_grad;
  torch::manual_seed(17);
  for (auto& p : op.parameters()) p.add_(torch::randn_like(p) * 0.7);
}

class GatBlockVsNaive : public ::testing::TestWithParam<GatCase> {};

TEST_P(GatBlockVsNaive, MatchesLoopReference) {
  const GatCase& c = GetParam();
  const TinyGraph t = grid();
  auto op = make_gat(c.yaml(), t.dims);
  perturb(*op);
  const Features out = op->forward(t.features, t.graph);
  const Naive ref = naive_gat(*op, c, t.features.vertex, t.graph.one_ring);
  EXPECT_EQ(out.vertex.sizes(), ref.out.sizes());
  EXPECT_EQ(out.vertex.size(1), op->out_dims().vertex);
  EXPECT_TRUE(torch::allclose(out.vertex, ref.out, 1e-10, 1e-12))
      << (out.vertex - ref.out).abs().max().item<double>();
  EXPECT_TRUE(torch::equal(out.bone, t.features.bone));  // bones pass through
  // the α the op reports are the reference's, on the same edges in the same order
  const GatBlock::Attention att = op->attention(t.features, t.graph);
  EXPECT_TRUE(torch::equal(att.edges, ref.edges));
  EXPECT_TRUE(torch::allclose(att.alpha, ref.alpha, 1e-10, 1e-12));
}

TEST_P(GatBlockVsNaive, AttentionOfEveryReceiverSumsToOne) {
  const GatCase& c = GetParam();
  const TinyGraph t = grid();
  auto op = make_gat(c.yaml(), t.dims);
  perturb(*op);
  const GatBlock::Attention att = op->attention(t.features, t.graph);
  ASSERT_EQ(att.alpha.size(1), c.heads);
  const torch::Tensor receiver = att.edges.select(1, 0);
  const torch::Tensor sums =
      torch::zeros({kGridVertices, c.heads}, torch::kFloat64).index_add(0, receiver, att.alpha);
  const torch::Tensor has = torch::bincount(receiver, {}, kGridVertices) > 0;
  EXPECT_TRUE(torch::allclose(sums.index({has}), torch::ones_like(sums.index({has})), 0, 1e-12));
  EXPECT_TRUE(((att.alpha > 0) & (att.alpha <= 1)).all().item<bool>());
  // the isolated vertex: only its self-loop (α = 1), or nothing at all
  EXPECT_EQ(has[kIsolated].item<bool>(), c.self_loops);
  // and its output is finite either way, σ(0 ‖ r + b) without self-loops
  const Features out = op->forward(t.features, t.graph);
  EXPECT_TRUE(torch::isfinite(out.vertex).all().item<bool>());
}

INSTANTIATE_TEST_SUITE_P(GatBlock, GatBlockVsNaive, ::testing::ValuesIn(all_cases()),
                         [](const auto& info) { return info.param.name(); });

// The gradient checks: a subset spanning every option value (each case costs ~1,000 forwards).
class GatBlockGradients : public ::testing::TestWithParam<GatCase> {};

TEST_P(GatBlockGradients, MatchFiniteDifferences) {
  const GatCase& c = GetParam();
  const TinyGraph t = grid(3);
  auto op = make_gat(c.yaml(), t.dims);
  perturb(*op);
  expect_gradients_match(*op, t.features, t.graph);
}

INSTANTIATE_TEST_SUITE_P(GatBlock, GatBlockGradients,
                         ::testing::Values(GatCase{3, true, true, 0.5, "tanhshrink"},
                                           GatCase{3, false, false, 0.5, "elu"},
                                           GatCase{1, true, false, 0.0, "none"},
                                           GatCase{3, true, false, 0.0, "tanhshrink"},
                                           GatCase{1, false, true, 1.0, "elu"}),
                         [](const auto& info) { return info.param.name(); });

// ---- the other edge set, unsorted and with a self-edge
// -----------------------------------------------------------------

TEST(GatBlock, GeodesicUnsortedWithASelfEdge) {
  // tiny_graph's geodesic set is asymmetric, unsorted and lists (5, 5); with self-loops that
  // edge is the self-loop, counted once
  const TinyGraph t = tiny_graph(3, 2);
  for (bool self_loops : {true, false}) {
    const GatCase c{3, true, self_loops, 0.5, "tanhshrink"};
    auto op = make_gat(c.yaml("geodesic"), t.dims);
    perturb(*op);
    const Naive ref = naive_gat(*op, c, t.features.vertex, t.graph.geodesic);
    EXPECT_TRUE(torch::allclose(op->forward(t.features, t.graph).vertex, ref.out, 1e-10, 1e-12))
        << self_loops;
    const GatBlock::Attention att = op->attention(t.features, t.graph);
    EXPECT_TRUE(torch::equal(att.edges, ref.edges)) << self_loops;
    EXPECT_TRUE(torch::allclose(att.alpha, ref.alpha, 1e-10, 1e-12)) << self_loops;
    expect_gradients_match(*op, t.features, t.graph);
  }
  auto op = make_gat("{type: gat_block, hidden: 2, heads: 2, edges: geodesic}", t.dims);
  Graph without = t.graph;
  without.geodesic = t.graph.geodesic.index_select(
      0, torch::tensor({0, 1, 2, 3, 4, 5, 7, 8}, torch::kInt64));  // (5, 5) is row 6
  EXPECT_TRUE(torch::allclose(op->forward(t.features, t.graph).vertex,
                              op->forward(t.features, without).vertex, 1e-12, 1e-14));
}

TEST(GatBlock, NegativeSlopeIsUsed) {
  const TinyGraph t = grid();
  const GatCase c{3, true, true, 0.5, "none"};
  auto op = make_gat(
      "{type: gat_block, hidden: 2, heads: 3, beta: 0.5, activation: none, "
      "negative_slope: 0.05}",
      t.dims);
  perturb(*op);
  EXPECT_TRUE(torch::allclose(op->forward(t.features, t.graph).vertex,
                              naive_gat(*op, c, t.features.vertex, t.graph.one_ring, 0.05).out,
                              1e-10, 1e-12));
}

// ---- invariances and edge cases
// -----------------------------------------------------------------------------------

TEST(GatBlock, RelabellingVerticesPermutesTheOutput) {
  const TinyGraph t = grid();
  for (bool self_loops : {true, false}) {
    auto op = make_gat(std::string("{type: gat_block, hidden: 3, heads: 2, beta: 0.5, "
                                   "self_loops: ") +
                           (self_loops ? "true}" : "false}"),
                       t.dims);
    perturb(*op);
    // new vertex v is old vertex perm[v]; an old index u becomes inverse[u]
    torch::manual_seed(5);
    const torch::Tensor perm = torch::randperm(kGridVertices, torch::kInt64);
    const torch::Tensor inverse = torch::argsort(perm);
    Graph relabelled = t.graph;
    relabelled.one_ring = inverse.index_select(0, t.graph.one_ring.view(-1)).view({-1, 2});
    ASSERT_FALSE((relabelled.one_ring.select(1, 0).diff() >= 0).all().item<bool>());  // unsorted
    const Features moved{t.features.vertex.index_select(0, perm), t.features.bone};
    const torch::Tensor expected = op->forward(t.features, t.graph).vertex.index_select(0, perm);
    EXPECT_TRUE(torch::allclose(op->forward(moved, relabelled).vertex, expected, 1e-12, 1e-14));
  }
}

TEST(GatBlock, IsolatedVerticesAndNoEdgesAtAll) {
  TinyGraph t = grid();
  auto op =
      make_gat("{type: gat_block, hidden: 2, heads: 3, beta: 0.5, self_loops: false}", t.dims);
  perturb(*op);
  // the isolated vertex aggregates nothing: σ(0 ‖ H g + b)
  const torch::Tensor b = param(*op, "bias"), h = param(*op, "h.weight");
  const torch::Tensor y =
      torch::cat({torch::zeros({6}, torch::kFloat64), h.mv(t.features.vertex[kIsolated])}) + b;
  EXPECT_TRUE(
      torch::allclose(op->forward(t.features, t.graph).vertex[kIsolated], y - torch::tanh(y)));
  // every edge dropped: finite everywhere, and the gradients too
  t.graph.one_ring = torch::zeros({0, 2}, torch::kInt64);
  const Features out = op->forward(t.features, t.graph);
  EXPECT_TRUE(torch::isfinite(out.vertex).all().item<bool>());
  EXPECT_EQ(op->attention(t.features, t.graph).alpha.size(0), 0);
  expect_gradients_match(*op, t.features, t.graph);
  // with self-loops each vertex attends to itself only (α = 1): the aggregation is W g_i
  auto looped = make_gat("{type: gat_block, hidden: 2, heads: 3, beta: 0}", t.dims);
  const torch::Tensor z = t.features.vertex.matmul(param(*looped, "w.weight").t());
  EXPECT_TRUE(torch::allclose(looped->forward(t.features, t.graph).vertex, z - torch::tanh(z)));
}

TEST(GatBlock, LargeLogitsDoNotOverflow) {
  // logits of ~1e4: exp overflows without the per-receiver max shift
  TinyGraph t = grid();
  auto op =
      make_gat("{type: gat_block, hidden: 2, heads: 3, activation: none}", t.dims, torch::kFloat32);
  {
    torch::NoGradGuard no_grad;
    param(*op, "a_dst").fill_(50);
    param(*op, "a_src").normal_(0, 50);
  }
  const Features in{(t.features.vertex * 100).to(torch::kFloat32),
                    t.features.bone.to(torch::kFloat32)};
  EXPECT_TRUE(torch::isfinite(op->forward(in, t.graph).vertex).all().item<bool>());
  const GatBlock::Attention att = op->attention(in, t.graph);
  EXPECT_TRUE(torch::isfinite(att.alpha).all().item<bool>());
  const torch::Tensor sums =
      torch::zeros({kGridVertices, 3}).index_add(0, att.edges.select(1, 0), att.alpha);
  EXPECT_TRUE(torch::allclose(sums, torch::ones_like(sums), 0, 1e-5));
}

TEST(GatBlock, Float32DeterministicAndCloseToFloat64) {
  const TinyGraph t = grid();
  auto op = make_gat("{type: gat_block, hidden: 4, heads: 3}", t.dims);
  perturb(*op);
  const torch::Tensor reference = op->forward(t.features, t.graph).vertex;
  op->to(torch::kFloat32);
  const Features in{t.features.vertex.to(torch::kFloat32), t.features.bone.to(torch::kFloat32)};
  const Features a = op->forward(in, t.graph), b = op->forward(in, t.graph);
  EXPECT_EQ(a.vertex.scalar_type(), torch::kFloat32);
  EXPECT_TRUE(torch::equal(a.vertex, b.vertex));
  EXPECT_TRUE(torch::allclose(a.vertex.to(torch::kFloat64), reference, 1e-4, 1e-5));
}

// ---- widths, parameters, init
// -------------------------------------------------------------------------------------

TEST(GatBlock, ThePapersBlockIs72Wide) {
  // Sec. 3.4: 8 heads of 8 hidden features, β = 0.125: 64 + 8 (Eq. 4, d = KF + βKF)
  auto op = graph_op_from(config::Config::parse("{type: gat_block}").root());
  EXPECT_EQ(op->build({72, 6, 3}), (Dims{72, 6, 3}));
  const auto& o = std::dynamic_pointer_cast<GatBlock>(op)->options();
  EXPECT_EQ(o.heads, 8);
  EXPECT_EQ(o.hidden, 8);
  EXPECT_EQ(o.beta, 0.125);
  EXPECT_EQ(o.edges, EdgeSet::kOneRing);
  EXPECT_TRUE(o.self_loops && o.concat);
  EXPECT_EQ(o.activation, GatBlock::Activation::kTanhshrink);
  EXPECT_EQ(o.negative_slope, 0.2);
  std::map<std::string, std::vector<int64_t>> shapes;
  for (const auto& p : op->named_parameters()) shapes[p.key()] = p.value().sizes().vec();
  EXPECT_EQ(shapes, (std::map<std::string, std::vector<int64_t>>{{"w.weight", {64, 72}},
                                                                 {"a_dst", {8, 8}},
                                                                 {"a_src", {8, 8}},
                                                                 {"h.weight", {8, 72}},
                                                                 {"bias", {72}}}));
  // Glorot-uniform bounds √(6 / (fan_in + fan_out)), zero bias
  const auto bound = [](double in, double out) { return std::sqrt(6.0 / (in + out)); };
  EXPECT_LE(param(*op, "w.weight").abs().max().item<double>(), bound(72, 64));
  EXPECT_GT(param(*op, "w.weight").abs().max().item<double>(), 0.9 * bound(72, 64));
  EXPECT_LE(param(*op, "a_src").abs().max().item<double>(), bound(8, 8));
  EXPECT_LE(param(*op, "h.weight").abs().max().item<double>(), bound(72, 8));
  EXPECT_EQ(param(*op, "bias").abs().max().item<double>(), 0.0);

  const auto width = [](const std::string& yaml) {
    auto o = graph_op_from(config::Config::parse(yaml).root());
    return o->build({5, 0, 0}).vertex;
  };
  EXPECT_EQ(width("{type: gat_block, beta: 0}"), 64);  // w/o self-reinforcement
  EXPECT_EQ(width("{type: gat_block, concat: false}"), 8 + 1);
  EXPECT_EQ(width("{type: gat_block, heads: 3, hidden: 5, beta: 0.3}"), 15 + 5);  // round(4.5)
  EXPECT_EQ(width("{type: gat_block, heads: 1, hidden: 4, beta: 2}"), 4 + 8);
  auto no_h = graph_op_from(config::Config::parse("{type: gat_block, beta: 0}").root());
  no_h->build({5, 0, 0});
  EXPECT_FALSE(param(*no_h, "h.weight").defined());
  EXPECT_EQ(no_h->named_children().size(), 1u);  // w only
}

// ---- errors
// -------------------------------------------------------------------------------------------------

TEST(GatBlock, ConfigErrors) {
  const auto parse = [](const std::string& yaml) {
    return graph_op_from(config::Config::parse(yaml, "test.yaml").root());
  };
  expect_error<ConfigError>(
      [&] { parse("{type: gat_block, head: 4}"); },
      {"test.yaml", "unknown field of graph_op 'gat_block'", "did you mean 'heads'?"});
  expect_error<ConfigError>([&] { parse("{type: gat_block, heads: 0}"); }, {"heads", "≥ 1"});
  expect_error<ConfigError>([&] { parse("{type: gat_block, hidden: -2}"); }, {"hidden", "≥ 1"});
  expect_error<ConfigError>([&] { parse("{type: gat_block, heads: two}"); }, {"heads"});
  expect_error<ConfigError>([&] { parse("{type: gat_block, beta: -0.1}"); }, {"beta", "≥ 0"});
  expect_error<ConfigError>([&] { parse("{type: gat_block, beta: 0.001}"); },
                            {"beta", "round(0.001 · 64) = 0", "beta: 0"});
  expect_error<ConfigError>([&] { parse("{type: gat_block, concat: false, beta: 0.05}"); },
                            {"beta", "round(0.05 · 8) = 0"});
  expect_error<ConfigError>([&] { parse("{type: gat_block, edges: skeleton}"); },
                            {"edges", "vertex edge set", "vertex features only"});
  expect_error<ConfigError>([&] { parse("{type: gat_block, edges: ring}"); },
                            {"edges", "unknown edge set 'ring'"});
  expect_error<ConfigError>([&] { parse("{type: gat_block, activation: relu}"); },
                            {"activation", "unknown activation 'relu'", "tanhshrink, elu, none"});
  expect_error<ConfigError>([&] { parse("{type: gat_block, negative_slope: -0.2}"); },
                            {"negative_slope", "[0, 1)"});
  expect_error<ConfigError>([&] { parse("{type: gat_block, self_loops: maybe}"); }, {"self_loops"});
}

TEST(GatBlock, BuildAndForwardErrorsNameTheOp) {
  const TinyGraph t = tiny_graph(3, 2);
  const std::string yaml = "{type: gat_block, heads: 2, hidden: 2}";
  expect_error<c10::Error>(
      [&] {
        make_op(yaml, Dims{0, 2, 2});
      },
      {"gat_block: needs vertex features, but their input width is 0"});
  auto unbuilt = graph_op_from(config::Config::parse(yaml).root());
  expect_error<c10::Error>([&] { unbuilt->forward(t.features, t.graph); },
                           {"gat_block: forward() before build()"});
  auto op = make_gat(yaml, t.dims);
  expect_error<c10::Error>([&] { op->build(t.dims); }, {"gat_block: build() called twice"});
  Features wide = t.features;
  wide.vertex = torch::randn({8, 4}, torch::kFloat64);
  expect_error<c10::Error>([&] { op->forward(wide, t.graph); },
                           {"gat_block: vertex features have width 4, but the op was built for "
                            "width 3"});
  expect_error<c10::Error>([&] { op->attention(wide, t.graph); }, {"gat_block: ", "width 4"});
  Features rows = t.features;
  rows.vertex = torch::randn({7, 3}, torch::kFloat64);
  expect_error<c10::Error>([&] { op->forward(rows, t.graph); },
                           {"gat_block: vertex features have 7 rows, but the graph has 8"});
  expect_error<c10::Error>([&] { op->forward(Features{}, t.graph); },
                           {"gat_block: needs vertex features", "got none"});
  // bone features are not needed
  EXPECT_NO_THROW(op->forward({t.features.vertex, {}}, t.graph));
  Graph bad = t.graph;
  bad.one_ring = t.graph.one_ring.clone();
  bad.one_ring[3][1] = 8;
  expect_error<c10::Error>([&] { op->forward(t.features, bad); },
                           {"gat_block: one_ring edge 3 is (2, 8), but the graph has 8 vertices"});
  bad.one_ring[3][1] = -1;
  expect_error<c10::Error>([&] { op->forward(t.features, bad); },
                           {"gat_block: one_ring edge 3 is (2, -1)"});
  auto geodesic = make_gat("{type: gat_block, heads: 2, hidden: 2, edges: geodesic}", t.dims);
  Graph none = t.graph;
  none.geodesic = torch::Tensor();
  expect_error<c10::Error>([&] { geodesic->forward(t.features, none); },
                           {"gat_block: the graph has no geodesic edges"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::graph

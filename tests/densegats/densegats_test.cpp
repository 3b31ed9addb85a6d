// The DenseGATs network (experiments/densegats/densegats.hpp): the paper's widths (Sec. 3.3,
// 3.4), the ablations and the original GAT as configs, gradients reaching every parameter and
// matching finite differences, batch normalisation only in training, and config errors.
#include "experiments/densegats/densegats.hpp"

#include <gtest/gtest.h>

#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/geometry/one_ring.hpp"
#include "tests/shapes/tube.hpp"

namespace skinlab::experiments {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

/// The one-ring graph of a small closed tube (8 sides × 5 rings + 2 cap centres = 42 vertices).
graph::Graph tube_graph() {
  const geometry::Mesh mesh =
      skinlab::testing::TubeBuilder().tube({0, 0, 0}, {0, 1, 0}, 0.2, 8, 5).build();
  const Eigen::Matrix2Xi e = geometry::one_ring(mesh).edges;
  graph::Graph g;
  g.one_ring = torch::empty({e.cols(), 2}, torch::kInt64);
  for (Eigen::Index k = 0; k < e.cols(); ++k) {
    g.one_ring[k][0] = e(0, k);
    g.one_ring[k][1] = e(1, k);
  }
  g.num_vertices = mesh.num_vertices();
  return g;
}

std::shared_ptr<models::CorrectiveModel> make(const std::string& yaml) {
  torch::manual_seed(0);
  return corrective_model_registry().create(config::Config::parse(yaml).root());
}

DenseGats& as_densegats(models::CorrectiveModel& m) { return dynamic_cast<DenseGats&>(m); }

/// Draws the parameters whose names start with `prefix` from N(0, sd²): the output layers start
/// at zero, which would stop every gradient behind them.
void randomize(models::CorrectiveModel& model, const std::string& prefix, double sd) {
  torch::NoGradGuard no_grad;
  for (auto& p : model.named_parameters()) {
    if (p.key().rfind(prefix, 0) == 0) p.value().normal_(0, sd);
  }
}

TEST(DenseGats, ThePapersNetworkHasItsWidths) {
  auto model = make("{type: densegats}");
  DenseGats& d = as_densegats(*model);
  // Module 1: 32 + 6·72 = 464 → transition 72 → module 2: 72 + 6·72 = 504 → transition 72 →
  // module 3: 504.
  EXPECT_EQ(d.trunk_width(), 504);
  EXPECT_EQ(d.input_width(), 52);
  std::size_t blocks = 0;
  for (const auto& child : model->named_children()) {
    const std::string& name = child.key();
    if (name.find("_block") != std::string::npos || name.rfind("transition", 0) == 0) {
      if (name.find("_norm") == std::string::npos) ++blocks;
    }
  }
  EXPECT_EQ(blocks, 3u * 6 + 2);
  const graph::Graph g = tube_graph();
  model->train();
  const torch::Tensor out = model->forward(torch::randn({g.num_vertices, 52}), g);
  EXPECT_EQ(out.sizes(), (std::vector<std::int64_t>{g.num_vertices, 3}));
  // The output layer starts at zero: training starts from plain LBS.
  EXPECT_EQ(out.abs().max().item<float>(), 0.0f);
}

TEST(DenseGats, AblationsAndTheOriginalGatAreConfigs) {
  EXPECT_EQ(as_densegats(*make("{type: densegats, dense: false}")).trunk_width(), 72);
  // Without the self-reinforced stream a block is 64 wide: 32 + 6·64, 64 + 6·64, twice.
  EXPECT_EQ(as_densegats(*make("{type: densegats, block: {type: gat_block, beta: 0}}")).trunk_width(),
            64 + 6 * 64);
  auto gat = make(
      "{type: densegats, modules: 1, blocks_per_module: 4, dense: false, feature_mlp: [], "
      "head: [], batch_norm: false, block: {type: gat_block, beta: 0, activation: elu}}");
  EXPECT_EQ(as_densegats(*gat).trunk_width(), 64);
  const graph::Graph g = tube_graph();
  EXPECT_EQ(gat->forward(torch::randn({g.num_vertices, 52}), g).size(1), 3);
  // The block is any graph op: a one-line change swaps the convolution.
  auto edge = make("{type: densegats, modules: 1, blocks_per_module: 2, "
                   "block: {type: edge_conv, edges: one_ring, mlp: [16]}}");
  EXPECT_EQ(as_densegats(*edge).trunk_width(), 32 + 2 * 16);
}

TEST(DenseGats, GradientsReachEveryParameter) {
  auto model = make("{type: densegats, modules: 2, blocks_per_module: 2}");
  randomize(*model, "out.", 0.1);
  const graph::Graph g = tube_graph();
  model->train();
  model->forward(torch::randn({g.num_vertices, 52}), g).pow(2).sum().backward();
  for (const auto& p : model->named_parameters()) {
    ASSERT_TRUE(p.value().grad().defined()) << p.key();
    EXPECT_GT(p.value().grad().abs().max().item<float>(), 0.0f) << p.key();
  }
}

TEST(DenseGats, GradientsMatchFiniteDifferences) {
  auto model = make(
      "{type: densegats, input_width: 5, feature_mlp: [4], modules: 2, blocks_per_module: 2, "
      "head: [4], batch_norm: false, block: {type: gat_block, heads: 2, hidden: 2, beta: 0.5}}");
  model->to(torch::kFloat64);
  randomize(*model, "out.", 0.5);
  const graph::Graph g = tube_graph();
  const torch::Tensor x = torch::randn({g.num_vertices, 5}, torch::kFloat64).requires_grad_();
  const torch::Tensor w = torch::randn({g.num_vertices, 3}, torch::kFloat64);
  const auto loss = [&](const torch::Tensor& in) { return (model->forward(in, g) * w).sum(); };
  loss(x).backward();
  const torch::Tensor analytic = x.grad().clone();
  torch::NoGradGuard no_grad;
  const double h = 1e-6;
  for (int k = 0; k < 12; ++k) {
    const std::int64_t v = (k * 7) % g.num_vertices, f = k % 5;
    torch::Tensor plus = x.detach().clone(), minus = x.detach().clone();
    plus[v][f] += h;
    minus[v][f] -= h;
    const double numeric = (loss(plus).item<double>() - loss(minus).item<double>()) / (2 * h);
    EXPECT_NEAR(analytic[v][f].item<double>(), numeric, 1e-6 * std::max(1.0, std::abs(numeric)))
        << "vertex " << v << " feature " << f;
  }
}

TEST(DenseGats, BatchStatisticsOnlyInTraining) {
  auto model = make("{type: densegats, modules: 1, blocks_per_module: 2}");
  randomize(*model, "out.", 0.1);
  const graph::Graph g = tube_graph();
  const torch::Tensor x = torch::randn({g.num_vertices, 52});
  model->eval();
  const torch::Tensor a = model->forward(x, g);
  EXPECT_TRUE(model->forward(x, g).equal(a));  // eval: running statistics, deterministic
  // In eval mode a vertex's output does not depend on the other vertices' inputs beyond its
  // receptive field; in training batch statistics couple them all.
  torch::Tensor y = x.clone();
  y[0] += 5;
  const std::int64_t far = g.num_vertices - 1;  // the other cap's centre
  EXPECT_TRUE(model->forward(y, g)[far].allclose(a[far]));
  model->train();
  EXPECT_FALSE(model->forward(y, g)[far].allclose(model->forward(x, g)[far]));
}

TEST(DenseGats, ConfigErrorsAreReportedAtConfigTime) {
  EXPECT_THROW(make("{type: densegats, modulez: 3}"), ConfigError);
  EXPECT_THROW(make("{type: densegats, modules: 0}"), ConfigError);
  EXPECT_THROW(make("{type: densegats, head: [0]}"), ConfigError);
  EXPECT_THROW(make("{type: densegats, block: {type: gat_blok}}"), RegistryError);
  EXPECT_THROW(make("{type: densegats, block: {type: gat_block, heads: 0}}"), ConfigError);
  auto model = make("{type: densegats, modules: 1, blocks_per_module: 1}");
  const graph::Graph g = tube_graph();
  try {
    model->forward(torch::randn({g.num_vertices, 51}), g);
    ADD_FAILURE() << "expected an error";
  } catch (const c10::Error& e) {
    EXPECT_NE(std::string(e.what()).find("densegats: expected #V×52"), std::string::npos) << e.what();
  }
}


TEST(NeuroSkinningCorrective, ThePaperWidthsGiveADisplacementThatStartsAtZero) {
  const config::Config file = config::Config::load(
      std::string(SKINLAB_SOURCE_DIR) + "/configs/densegats/neuroskinning.yaml");
  torch::manual_seed(0);
  auto model = corrective_model_registry().create(file.root()["model"]);
  EXPECT_EQ(model->input_width(), 52);
  const graph::Graph g = tube_graph();
  const torch::Tensor x = torch::randn({g.num_vertices, 52});
  const torch::Tensor out = model->forward(x, g);
  EXPECT_EQ(out.sizes(), (std::vector<std::int64_t>{g.num_vertices, 3}));
  EXPECT_EQ(out.abs().max().item<float>(), 0.0f);
  // The skinning network's layer names (input, stem, local, global_branch, head), one of them
  // the 1024-wide global feature.
  bool global = false;
  for (const auto& p : model->named_parameters()) {
    global |= p.key().rfind("global_branch.", 0) == 0 && p.value().size(0) == 1024;
  }
  EXPECT_TRUE(global);
  randomize(*model, "head.linear2", 0.1);
  model->forward(x, g).pow(2).sum().backward();
  for (const auto& p : model->named_parameters()) {
    ASSERT_TRUE(p.value().grad().defined()) << p.key();
    EXPECT_GT(p.value().grad().abs().max().item<float>(), 0.0f) << p.key();
  }
  EXPECT_THROW(model->forward(torch::randn({g.num_vertices, 50}), g), c10::Error);
  EXPECT_THROW(corrective_model_registry().create(
                   config::Config::parse("{type: neuroskinning, top_kk: 3}").root()),
               ConfigError);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::experiments

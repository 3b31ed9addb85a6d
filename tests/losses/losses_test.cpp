// Losses: hand-computed values, a naive loop reference, finite-difference gradients, and the
// weighted sum built from a `losses:` config list.

#include <gtest/gtest.h>

#include <cmath>

#include "framework/core/registry.hpp"
#include "framework/losses/kl.hpp"
#include "framework/losses/laplacian_smoothing.hpp"
#include "framework/losses/loss.hpp"
#include "framework/losses/mse.hpp"
#include "framework/losses/prior_kl.hpp"
#include "framework/losses/soft_cross_entropy.hpp"
#include "tests/test_util.hpp"

namespace skinlab::losses {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;

std::shared_ptr<Loss> make(const std::string& yaml) {
  return loss_registry().create(config::Config::parse(yaml, "test.yaml").root());
}

torch::Tensor rows(std::vector<std::vector<double>> values) {
  const auto n = static_cast<int64_t>(values.size());
  const auto c = static_cast<int64_t>(values[0].size());
  torch::Tensor t = torch::empty({n, c}, torch::kFloat64);
  for (int64_t i = 0; i < n; ++i)
    for (int64_t j = 0; j < c; ++j) t[i][j] = values[i][j];
  return t;
}

/// Random row distributions with some exact zeros in the target, as ground-truth skin weights.
std::pair<torch::Tensor, torch::Tensor> random_distributions(int64_t n, int64_t c) {
  torch::manual_seed(7);
  const torch::Tensor pred = torch::softmax(torch::randn({n, c}, torch::kFloat64), 1);
  torch::Tensor target = torch::rand({n, c}, torch::kFloat64);
  target = torch::where(target < 0.3, torch::zeros_like(target), target);
  target.select(1, 0).add_(1e-3);  // keep every row non-empty
  return {pred, target / target.sum(1, true)};
}

/// Central finite differences of `f` with respect to `x`, compared with autograd.
void expect_gradient_matches(const std::function<torch::Tensor(const torch::Tensor&)>& f,
                             torch::Tensor x) {
  x = x.clone().set_requires_grad(true);
  const torch::Tensor analytic = torch::autograd::grad({f(x)}, {x})[0];
  const double h = 1e-6;
  auto flat = x.detach().clone();
  for (int64_t i = 0; i < flat.numel(); ++i) {
    auto plus = flat.clone(), minus = flat.clone();
    plus.view(-1)[i] += h;
    minus.view(-1)[i] -= h;
    const double numeric = (f(plus).item<double>() - f(minus).item<double>()) / (2 * h);
    EXPECT_NEAR(analytic.view(-1)[i].item<double>(), numeric, 1e-5) << "entry " << i;
  }
}

TEST(KlLoss, HandComputedValues) {
  const auto kl = make("{type: kl}");
  // one-hot target: KL = -log(p of the true bone)
  EXPECT_NEAR((*kl)({rows({{0.5, 0.5}}), rows({{1.0, 0.0}})}).item<double>(), std::log(2.0), 1e-12);
  // identical distributions: 0
  EXPECT_NEAR((*kl)({rows({{0.2, 0.3, 0.5}}), rows({{0.2, 0.3, 0.5}})}).item<double>(), 0.0, 1e-12);
  // mean over rows: (log 2 + log 4) / 2
  EXPECT_NEAR((*kl)({rows({{0.5, 0.5}, {0.25, 0.75}}), rows({{1, 0}, {1, 0}})}).item<double>(),
              (std::log(2.0) + std::log(4.0)) / 2, 1e-12);
}

TEST(KlLoss, MatchesNaiveLoopAndHasFiniteGradientsWithZeroTargets) {
  auto [pred, target] = random_distributions(20, 5);
  const auto kl = make("{type: kl, eps: 1e-12}");
  double naive = 0;
  for (int64_t i = 0; i < pred.size(0); ++i)
    for (int64_t j = 0; j < pred.size(1); ++j) {
      const double t = target[i][j].item<double>(), p = pred[i][j].item<double>();
      if (t > 0) naive += t * std::log(t / p);
    }
  EXPECT_NEAR((*kl)({pred, target}).item<double>(), naive / 20, 1e-10);
  expect_gradient_matches([&](const torch::Tensor& p) { return (*kl)({p, target}); }, pred);
}

TEST(SoftCrossEntropyLoss, EqualsKlPlusTargetEntropy) {
  auto [pred, target] = random_distributions(10, 4);
  const auto kl = make("{type: kl}");
  const auto ce = make("{type: soft_cross_entropy}");
  const torch::Tensor entropy =
      -torch::where(target > 0, target * torch::log(target), torch::zeros_like(target)).sum(1).mean();
  EXPECT_NEAR((*ce)({pred, target}).item<double>(),
              ((*kl)({pred, target}) + entropy).item<double>(), 1e-10);
  expect_gradient_matches([&](const torch::Tensor& p) { return (*ce)({p, target}); }, pred);
}

TEST(PriorKlLoss, KlAgainstThePriorRenormalisedAndZeroWhereThePriorIsEmpty) {
  const auto anchor = make("{type: prior_kl, prior: bone_heat}");
  LossInputs in{rows({{0.5, 0.5, 0.0}, {0.2, 0.3, 0.5}})};
  // Row 0: prior (0.3, 0.1, 0) renormalises to (0.75, 0.25, 0); row 1: no prior weight at all.
  in.priors["bone_heat"] = rows({{0.3, 0.1, 0.0}, {0.0, 0.0, 0.0}});
  const double row0 = 0.75 * std::log(0.75 / 0.5) + 0.25 * std::log(0.25 / 0.5);
  EXPECT_NEAR((*anchor)(in).item<double>(), row0 / 2, 1e-12);
  // A prediction equal to the renormalised prior costs nothing.
  in.pred = rows({{0.75, 0.25, 0.0}, {0.2, 0.3, 0.5}});
  EXPECT_NEAR((*anchor)(in).item<double>(), 0.0, 1e-12);
}

TEST(PriorKlLoss, NextToKlItIsKlAgainstTheMixedTarget) {
  // kl + β prior_kl has the gradient of (1 + β) kl against (ŵ + β q) / (1 + β): the anchor pulls
  // the optimum towards the prior by 1 / (1 + β) (prior_kl.hpp).
  auto [pred, target] = random_distributions(12, 4);
  torch::Tensor prior = torch::rand({12, 4}, torch::kFloat64);
  prior.select(1, 3).zero_();  // the prior leaves a candidate at 0
  const torch::Tensor q = prior / prior.sum(1, true);
  const double beta = 0.5;
  const LossSum anchored = LossSum::from(
      config::Config::parse("losses: [{type: kl}, {type: prior_kl, prior: bone_heat, weight: 0.5}]")
          .root()["losses"]);
  const auto kl = make("{type: kl}");
  const torch::Tensor mixed = (target + beta * q) / (1 + beta);
  const auto grad = [](const std::function<torch::Tensor(const torch::Tensor&)>& f,
                       const torch::Tensor& x) {
    const torch::Tensor p = x.clone().set_requires_grad(true);
    return torch::autograd::grad({f(p)}, {p})[0];
  };
  const torch::Tensor g_anchored = grad(
      [&](const torch::Tensor& p) {
        LossInputs in{p, target};
        in.priors["bone_heat"] = prior;
        return anchored(in);
      },
      pred);
  const torch::Tensor g_mixed =
      grad([&](const torch::Tensor& p) { return (1 + beta) * (*kl)({p, mixed}); }, pred);
  EXPECT_TRUE(torch::allclose(g_anchored, g_mixed, 1e-9, 1e-12));
}

TEST(PriorKlLoss, Errors) {
  const auto anchor = make("{type: prior_kl, prior: bone_heat}");
  LossInputs in{rows({{0.5, 0.5}})};
  expect_error<c10::Error>([&] { (*anchor)(in); },
                           {"prior_kl: no 'bone_heat' prior", "has: none", "preprocess.priors"});
  in.priors["geo_voxel"] = rows({{1.0, 0.0}});
  expect_error<c10::Error>([&] { (*anchor)(in); }, {"has: geo_voxel"});
  in.priors["bone_heat"] = rows({{1.0, 0.0, 0.0}});
  expect_error<c10::Error>([&] { (*anchor)(in); }, {"prior shape", "prediction shape"});
  expect_error<ConfigError>([&] { make("{type: prior_kl}"); }, {"prior"});
}

TEST(LossSum, NamesThePriorsItsTermsReadOnceEach) {
  const auto sum = [](const std::string& list) {
    return LossSum::from(config::Config::parse("losses: " + list).root()["losses"]).priors();
  };
  EXPECT_TRUE(sum("[{type: kl}, {type: laplacian_smoothing}]").empty());
  EXPECT_EQ(sum("[{type: prior_kl, prior: geo_voxel}, {type: kl}, {type: prior_kl, prior: "
                "bone_heat}, {type: prior_kl, prior: geo_voxel, weight: 2}]"),
            (std::vector<std::string>{"bone_heat", "geo_voxel"}));
}

TEST(MseLoss, PerRowAndPerElement) {
  const torch::Tensor p = rows({{1, 2}, {0, 0}});
  const torch::Tensor t = rows({{0, 0}, {0, 1}});
  EXPECT_NEAR((*make("{type: mse}"))({p, t}).item<double>(), (5.0 + 1.0) / 2, 1e-12);
  EXPECT_NEAR((*make("{type: mse, per_element: true}"))({p, t}).item<double>(), 6.0 / 4, 1e-12);
}

TEST(LaplacianSmoothingLoss, PathGraphByHandSparseEqualsDense) {
  // Path 0-1-2, L = D - A. For w = (1, 0, 0): wᵀLw = 1; for w = (0, 1, 1): wᵀLw = 1.
  const torch::Tensor dense = rows({{1, -1, 0}, {-1, 2, -1}, {0, -1, 1}});
  const torch::Tensor w = rows({{1, 0}, {0, 1}, {0, 1}});
  const auto lap = make("{type: laplacian_smoothing}");
  EXPECT_NEAR((*lap)({w, {}, dense}).item<double>(), 2.0 / 3, 1e-12);
  EXPECT_NEAR((*lap)({w, {}, dense.to_sparse()}).item<double>(), 2.0 / 3, 1e-12);
  // constant weights are perfectly smooth
  EXPECT_NEAR((*lap)({torch::ones({3, 2}, torch::kFloat64), {}, dense}).item<double>(), 0, 1e-12);
  expect_gradient_matches([&](const torch::Tensor& p) { return (*lap)({p, {}, dense}); },
                          torch::rand({3, 2}, torch::kFloat64));
}

TEST(Losses, ArgumentChecks) {
  const auto kl = make("{type: kl}");
  EXPECT_THROW((*kl)({rows({{0.5, 0.5}}), rows({{1, 0, 0}})}), c10::Error);
  EXPECT_THROW((*kl)({rows({{0.5, 0.5}}), {}}), c10::Error);
  const auto lap = make("{type: laplacian_smoothing}");
  EXPECT_THROW((*lap)({rows({{0.5, 0.5}}), {}, {}}), c10::Error);
  EXPECT_THROW((*lap)({rows({{0.5, 0.5}}), {}, torch::eye(2, torch::kFloat64)}), c10::Error);
}

TEST(LossSum, WeightedSumFromConfig) {
  const auto config = config::Config::parse(
      "losses:\n  - {type: kl, weight: 1.0}\n  - {type: laplacian_smoothing, weight: 0.4}\n"
      "  - {type: kl, weight: 0.5}\n");
  const LossSum sum = LossSum::from(config.root()["losses"]);
  ASSERT_EQ(sum.terms().size(), 3u);
  const torch::Tensor w = rows({{1, 0}, {0, 1}, {0, 1}});
  const torch::Tensor t = rows({{0.5, 0.5}, {0, 1}, {0, 1}});
  const torch::Tensor lap = rows({{1, -1, 0}, {-1, 2, -1}, {0, -1, 1}});
  std::map<std::string, double> parts;
  const double total = sum({w, t, lap}, &parts).item<double>();
  EXPECT_EQ(parts.size(), 3u);
  EXPECT_NEAR(parts["laplacian_smoothing"], 2.0 / 3, 1e-12);
  EXPECT_NEAR(parts["kl"], parts["kl#2"], 1e-12);
  EXPECT_NEAR(total, 1.5 * parts["kl"] + 0.4 * parts["laplacian_smoothing"], 1e-12);
}

TEST(LossSum, ConfigErrors) {
  auto build = [](const std::string& yaml) {
    return LossSum::from(config::Config::parse(yaml, "l.yaml").root()["losses"]);
  };
  expect_error<RegistryError>([&] { build("losses: [{type: kll}]"); },
                              {"l.yaml:1: losses[0]: ", "unknown loss type 'kll'",
                               "kl, laplacian_smoothing, mse, prior_kl, soft_cross_entropy"});
  expect_error<ConfigError>([&] { build("losses: [{type: kl, weight: -1}]"); },
                            {"losses[0].weight: must be a finite number"});
  expect_error<ConfigError>([&] { build("losses: [{type: kl, epz: 1e-6}]"); },
                            {"losses[0].epz: unknown field of loss 'kl'", "did you mean 'eps'?",
                             "known fields: eps, type, weight"});
  expect_error<ConfigError>([&] { build("losses: []"); }, {"non-empty list of losses"});
  expect_error<ConfigError>([&] { build("losses: [{type: kl, eps: 2}]"); },
                            {"losses[0].eps: must be in (0, 1)"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::losses

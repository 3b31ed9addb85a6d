// avg_l1: hand-computed values on pruned and raw predictions, and a torch reference.

#include "framework/eval/avg_l1.hpp"

#include <gtest/gtest.h>

#include "tests/eval/eval_fixtures.hpp"

namespace skinlab::eval {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::make_metric;
using testing::weights;

const torch::Tensor kPred = weights({{0.7, 0.2, 0.1, 0}, {0.5, 0.5, 0, 0}, {0, 0, 0.9, 0.1}});
const torch::Tensor kTarget = weights({{0.99995, 0, 0, 0.00005}, {0.5, 0, 0.5, 0}, {0, 0, 1, 0}});

TEST(AvgL1, PrunedPredictionByHand) {
  // Pruned rows: (7/9, 2/9, 0, 0), (0.5, 0.5, 0, 0), (0, 0, 1, 0).
  //   row 0: (0.99995 − 7/9) + 2/9 + 0.00005 = 4/9;  row 1: 0.5 + 0.5 = 1;  row 2: 0.
  const auto values = (*make_metric("{type: avg_l1}"))({kPred, kTarget});
  EXPECT_NEAR(values.at("avg_l1"), (4.0 / 9 + 1 + 0) / 3, 1e-6);  // float32 inputs
  EXPECT_EQ(values.size(), 1u);
}

TEST(AvgL1, RawPredictionByHand) {
  //   row 0: 0.29995 + 0.2 + 0.1 + 0.00005 = 0.6;  row 1: 1;  row 2: 0.1 + 0.1 = 0.2.
  const auto values = (*make_metric("{type: avg_l1, prune: 0}"))({kPred, kTarget});
  EXPECT_NEAR(values.at("avg_l1"), (0.6 + 1 + 0.2) / 3, 1e-6);
}

TEST(AvgL1, ZeroForAPerfectPredictionTwoForDisjointOnes) {
  EXPECT_DOUBLE_EQ((*make_metric("{type: avg_l1, prune: 0}"))({kTarget, kTarget}).at("avg_l1"),
                   0.0);
  // Pruned as a prediction, the ground truth loses its 5e-5 weight (row 0 becomes (1, 0, 0, 0)):
  // L1 2 · 5e-5 on one row of three.
  EXPECT_NEAR((*make_metric("{type: avg_l1}"))({kTarget, kTarget}).at("avg_l1"), 1e-4 / 3, 1e-8);
  const torch::Tensor a = weights({{1, 0, 0}, {0, 0.5, 0.5}});
  const torch::Tensor b = weights({{0, 1, 0}, {1, 0, 0}});
  EXPECT_DOUBLE_EQ((*make_metric("{type: avg_l1}"))({a, b}).at("avg_l1"), 2.0);
}

TEST(AvgL1, MatchesATorchReferenceOnRandomWeights) {
  const torch::Tensor pred = testing::random_weights(300, 20, 5, 3);
  const torch::Tensor target = testing::random_weights(300, 20, 3, 4);
  torch::Tensor p = pred.to(torch::kFloat64);
  p = torch::where(p < 0.25 * p.amax(1, true), torch::zeros_like(p), p);
  p = p / p.sum(1, true);
  const double expected = (p - target.to(torch::kFloat64)).abs().sum(1).mean().item<double>();
  EXPECT_NEAR((*make_metric("{type: avg_l1}"))({pred, target}).at("avg_l1"), expected, 1e-12);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::eval

// precision_recall: hand-counted cases (pruning, threshold, both averages, empty sets) and a
// torch reference on random weights.

#include "framework/eval/precision_recall.hpp"

#include <gtest/gtest.h>

#include "tests/eval/eval_fixtures.hpp"

namespace skinlab::eval {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::make_metric;
using testing::weights;

// Pruning at 0.25 × the row maximum: row 0 drops 0.1 (< 0.175), row 2 drops 0.1 (< 0.225).
//   predicted influences: {0, 1}, {0, 1}, {2}        → 5
//   ground truth (> 1e-4): {0}, {0, 2}, {2}          → 4 (5e-5 on bone 3 of row 0 is below)
//   both: {0}, {0}, {2}                              → 3
const torch::Tensor kPred = weights({{0.7, 0.2, 0.1, 0}, {0.5, 0.5, 0, 0}, {0, 0, 0.9, 0.1}});
const torch::Tensor kTarget = weights({{0.99995, 0, 0, 0.00005}, {0.5, 0, 0.5, 0}, {0, 0, 1, 0}});

TEST(PrecisionRecall, CountsOverAllEntriesOfTheCharacter) {
  const auto values = (*make_metric("{type: precision_recall}"))({kPred, kTarget});
  EXPECT_DOUBLE_EQ(values.at("precision"), 3.0 / 5);
  EXPECT_DOUBLE_EQ(values.at("recall"), 3.0 / 4);
  EXPECT_EQ(values.size(), 2u);
}

TEST(PrecisionRecall, PerVertexAverage) {
  // precision per vertex 1/2, 1/2, 1/1; recall 1/1, 1/2, 1/1.
  const auto values =
      (*make_metric("{type: precision_recall, average: vertices}"))({kPred, kTarget});
  EXPECT_DOUBLE_EQ(values.at("precision"), (0.5 + 0.5 + 1) / 3);
  EXPECT_DOUBLE_EQ(values.at("recall"), (1 + 0.5 + 1) / 3);
}

TEST(PrecisionRecall, WithoutPruningEverySmallWeightCounts) {
  // predicted {0, 1, 2}, {0, 1}, {2, 3} → 7; both still 3.
  const auto values = (*make_metric("{type: precision_recall, prune: 0}"))({kPred, kTarget});
  EXPECT_DOUBLE_EQ(values.at("precision"), 3.0 / 7);
  EXPECT_DOUBLE_EQ(values.at("recall"), 3.0 / 4);
}

TEST(PrecisionRecall, ThresholdDecidesTheGroundTruthInfluences) {
  // At 1e-5 the 5e-5 weight of row 0 on bone 3 is an influence: ground truth 5, both 3.
  const auto values =
      (*make_metric("{type: precision_recall, threshold: 1.0e-5}"))({kPred, kTarget});
  EXPECT_DOUBLE_EQ(values.at("precision"), 3.0 / 5);
  EXPECT_DOUBLE_EQ(values.at("recall"), 3.0 / 5);
  // The ground truth is never pruned: with prune 1 the prediction keeps only row maxima
  // ({0}, {0, 1}, {2}: 4, both 3) while the ground truth keeps its 0.5/0.5 row.
  const auto strict = (*make_metric("{type: precision_recall, prune: 1}"))({kPred, kTarget});
  EXPECT_DOUBLE_EQ(strict.at("precision"), 3.0 / 4);
  EXPECT_DOUBLE_EQ(strict.at("recall"), 3.0 / 4);
}

TEST(PrecisionRecall, PerfectAndEmptyPredictions) {
  const auto perfect = (*make_metric("{type: precision_recall}"))({kTarget, kTarget});
  EXPECT_DOUBLE_EQ(perfect.at("precision"), 1.0);
  EXPECT_DOUBLE_EQ(perfect.at("recall"), 1.0);
  // No predicted influence at all: precision has a zero denominator and is reported as 0.
  const torch::Tensor none = torch::zeros_like(kTarget);
  for (const char* average : {"entries", "vertices"}) {
    const auto values = (*make_metric(std::string("{type: precision_recall, average: ") + average +
                                      "}"))({none, kTarget});
    EXPECT_DOUBLE_EQ(values.at("precision"), 0.0) << average;
    EXPECT_DOUBLE_EQ(values.at("recall"), 0.0) << average;
  }
}

TEST(PrecisionRecall, MatchesATorchReferenceOnRandomWeights) {
  const torch::Tensor pred = testing::random_weights(300, 20, 5, 1);
  const torch::Tensor target = testing::random_weights(300, 20, 3, 2);
  torch::Tensor p = pred.to(torch::kFloat64), g = target.to(torch::kFloat64);
  p = torch::where(p < 0.25 * p.amax(1, true), torch::zeros_like(p), p);
  p = p / p.sum(1, true);
  const torch::Tensor pi = p > 1e-4, gi = g > 1e-4, both = pi.logical_and(gi);
  const auto values = (*make_metric("{type: precision_recall}"))({pred, target});
  const double tp = both.sum().item<double>();
  EXPECT_NEAR(values.at("precision"), tp / pi.sum().item<double>(), 1e-12);
  EXPECT_NEAR(values.at("recall"), tp / gi.sum().item<double>(), 1e-12);
  const auto per_vertex =
      (*make_metric("{type: precision_recall, average: vertices}"))({pred, target});
  const torch::Tensor b = both.sum(1).to(torch::kFloat64);
  EXPECT_NEAR(per_vertex.at("precision"), (b / pi.sum(1).to(torch::kFloat64)).mean().item<double>(),
              1e-12);
  EXPECT_NEAR(per_vertex.at("recall"), (b / gi.sum(1).to(torch::kFloat64)).mean().item<double>(),
              1e-12);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::eval

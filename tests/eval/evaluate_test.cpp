// make_metrics (a `metrics:` list through the registry) and mean_over_characters.

#include "framework/eval/evaluate.hpp"

#include <gtest/gtest.h>

#include "framework/eval/deformation_error.hpp"
#include "framework/eval/precision_recall.hpp"
#include "tests/eval/eval_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::eval {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;

std::vector<std::shared_ptr<Metric>> build(const std::string& yaml) {
  return make_metrics(config::Config::parse(yaml, "m.yaml").root()["metrics"]);
}

TEST(MakeMetrics, BuildsTheListInOrderWithOptions) {
  const auto metrics = build(
      "metrics:\n"
      "  - {type: precision_recall, threshold: 1.0e-3, average: vertices}\n"
      "  - {type: avg_l1}\n"
      "  - {type: deformation_error, poses: 4, seed: 9}\n");
  ASSERT_EQ(metrics.size(), 3u);
  const auto pr = std::dynamic_pointer_cast<PrecisionRecall>(metrics[0]);
  ASSERT_TRUE(pr);
  EXPECT_EQ(pr->options().threshold, 1e-3);
  EXPECT_EQ(pr->options().average, PrecisionRecall::Average::kVertices);
  EXPECT_EQ(metrics[1]->names(), std::vector<std::string>{"avg_l1"});
  const auto de = std::dynamic_pointer_cast<DeformationError>(metrics[2]);
  ASSERT_TRUE(de);
  EXPECT_EQ(de->options().poses, 4);
  EXPECT_EQ(de->options().seed, 9);
  // The per-character rows the evaluator merges.
  const auto arm = testing::two_joint_arm();
  const torch::Tensor gt = testing::weights({{1, 0}, {0, 1}, {0.5, 0.5}});
  std::map<std::string, double> row;
  for (const auto& m : metrics) row.merge((*m)({gt, gt, &arm}));
  EXPECT_EQ(row, (std::map<std::string, double>{{"avg_l1", 0},
                                                {"deformation_error", 0},
                                                {"deformation_error_max", 0},
                                                {"precision", 1},
                                                {"recall", 1}}));
}

TEST(MakeMetrics, RejectsDuplicateOutputNames) {
  expect_error<ConfigError>(
      [&] {
        build(
            "metrics:\n  - {type: precision_recall}\n  - {type: avg_l1}\n"
            "  - {type: precision_recall, average: vertices}\n");
      },
      {"m.yaml:4: metrics[2]: ", "metric 'precision_recall' reports 'precision'",
       "metrics[0] (type 'precision_recall') reports already"});
}

TEST(MakeMetrics, RejectsBadListsTypesAndOptions) {
  expect_error<ConfigError>([&] { build("metrics: []"); }, {"non-empty list of metrics"});
  expect_error<ConfigError>([&] { build("metrics: {type: avg_l1}"); },
                            {"m.yaml:1: metrics: ", "non-empty list of metrics"});
  expect_error<ConfigError>([&] { build("other: 1"); }, {"non-empty list of metrics"});
  expect_error<RegistryError>([&] { build("metrics:\n  - {type: avg_l2}\n"); },
                              {"m.yaml:2: metrics[0]: ", "unknown metric type 'avg_l2'",
                               "known metric types: avg_l1, deformation_error, dominant_joint, precision_recall"});
  expect_error<ConfigError>([&] { build("metrics:\n  - {type: avg_l1, prune: 2}\n"); },
                            {"m.yaml:2: metrics[0].prune: must be in [0, 1]"});
}

TEST(MeanOverCharacters, AveragesEveryNameWithCharactersCountingEqually) {
  const auto mean = mean_over_characters({{{"precision", 0.5}, {"avg_l1", 0.25}},
                                          {{"precision", 1.0}, {"avg_l1", 0.5}},
                                          {{"precision", 0.0}, {"avg_l1", 0.0}}});
  EXPECT_EQ(mean, (std::map<std::string, double>{{"avg_l1", 0.25}, {"precision", 0.5}}));
  EXPECT_TRUE(mean_over_characters({}).empty());
  // A value undefined for a character (NaN) is left out of its mean; all undefined: NaN.
  EXPECT_EQ(mean_over_characters({{{"a", 1.0}}, {{"a", std::nan("")}}, {{"a", 0.5}}}).at("a"), 0.75);
  EXPECT_TRUE(std::isnan(mean_over_characters({{{"a", std::nan("")}}, {{"a", std::nan("")}}}).at("a")));
}

TEST(MeanOverCharacters, DifferentNamesAreAnError) {
  expect_error<Error>(
      [&] {
        mean_over_characters({{{"a", 1}, {"b", 2}}, {{"a", 1}, {"b", 2}}, {{"a", 1}}});
      },
      {"character 2 reports {a}", "character 0 reports {a, b}"});
  expect_error<Error>(
      [&] {
        mean_over_characters({{{"a", 1}}, {{"c", 1}}});
      },
      {"character 1 reports {c}"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::eval

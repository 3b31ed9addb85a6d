// Every registered metric: a perfect prediction gets the ideal values, names() lists exactly
// what operator() returns, results are deterministic, and bad options give clear errors.

#include <gtest/gtest.h>

#include "framework/core/registry.hpp"
#include "framework/eval/metric.hpp"
#include "framework/eval/value_display.hpp"
#include "tests/eval/eval_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::eval {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using skinlab::testing::make_metric;

class EveryMetric : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryMetric, IdealValuesNamesAndDeterminism) {
  const auto metric = make_metric("{type: " + GetParam() + "}");
  const auto c = testing::random_character(10, 50, 1);
  const torch::Tensor gt = testing::random_weights(50, c.num_bones(), 3, 2);
  const torch::Tensor pred = testing::random_weights(50, c.num_bones(), 3, 3);
  const auto perfect = (*metric)({gt, gt, &c});
  std::vector<std::string> returned;
  for (const auto& [name, value] : perfect) {
    returned.push_back(name);
    // Pruning only removes predicted influences, so every one left is a true one; the ground
    // truth's own small weights are pruned away, so recall and the errors are not ideal here.
    if (name == "precision") {
      EXPECT_DOUBLE_EQ(value, 1.0);
    }
    EXPECT_TRUE(std::isfinite(value) && value >= 0) << name << " = " << value;
  }
  auto names = metric->names();
  std::sort(names.begin(), names.end());
  EXPECT_EQ(returned, names);
  // Without pruning, a perfect prediction is exactly ideal.
  const auto raw = make_metric("{type: " + GetParam() + ", prune: 0}");
  for (const auto& [name, value] : (*raw)({gt, gt, &c})) {
    // A score (higher is better: precision, recall, dominant_joint) is 1, an error 0.
    const bool is_score = value_display(name).higher_better;
    EXPECT_EQ(value, is_score ? 1.0 : 0.0) << name;
  }
  EXPECT_EQ((*metric)({pred, gt, &c}), (*metric)({pred, gt, &c}));
  EXPECT_EQ((*make_metric("{type: " + GetParam() + "}"))({pred, gt, &c}),
            (*metric)({pred, gt, &c}));
}

TEST_P(EveryMetric, RejectsUnknownFieldsAndBadPrune) {
  expect_error<ConfigError>(
      [&] { make_metric("{type: " + GetParam() + ", prnue: 0.1}"); },
      {"prnue: unknown field of metric '" + GetParam() + "'", "did you mean 'prune'?"});
  expect_error<ConfigError>([&] { make_metric("{type: " + GetParam() + ", prune: -0.1}"); },
                            {"prune: must be in [0, 1]"});
  expect_error<ConfigError>([&] { make_metric("{type: " + GetParam() + ", prune: high}"); },
                            {"prune: expected a number, got 'high'"});
}

INSTANTIATE_TEST_SUITE_P(Registered, EveryMetric, ::testing::ValuesIn(metric_registry().keys()),
                         [](const auto& info) { return info.param; });

TEST(MetricOptions, PrecisionRecallErrors) {
  expect_error<ConfigError>([&] { make_metric("{type: precision_recall, threshold: -1}"); },
                            {"test.yaml:1: threshold: must be in [0, 1)"});
  expect_error<ConfigError>([&] { make_metric("{type: precision_recall, threshold: 1}"); },
                            {"threshold: must be in [0, 1)"});
  expect_error<ConfigError>([&] { make_metric("{type: precision_recall, average: mean}"); },
                            {"average: must be 'entries' or 'vertices', got 'mean'"});
  expect_error<ConfigError>(
      [&] { make_metric("{type: precision_recall, treshold: 0.1}"); },
      {"did you mean 'threshold'?", "known fields: average, prune, threshold, type"});
}

TEST(MetricOptions, DeformationErrorErrors) {
  expect_error<ConfigError>([&] { make_metric("{type: deformation_error, poses: 0}"); },
                            {"poses: must be at least 1"});
  expect_error<ConfigError>([&] { make_metric("{type: deformation_error, poses: 2.5}"); },
                            {"poses: expected an integer, got '2.5'"});
  expect_error<ConfigError>([&] { make_metric("{type: deformation_error, fraction: 1.5}"); },
                            {"fraction: must be in [0, 1]"});
  expect_error<ConfigError>([&] { make_metric("{type: deformation_error, sigma_degrees: 0}"); },
                            {"sigma_degrees: must be in (0, 180] (degrees)"});
  expect_error<ConfigError>([&] { make_metric("{type: deformation_error, seed: x}"); },
                            {"seed: expected an integer"});
  expect_error<ConfigError>([&] { make_metric("{type: deformation_error, sigma: 25}"); },
                            {"unknown field of metric 'deformation_error'",
                             "known fields: fraction, poses, prune, seed, sigma_degrees, type"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::eval

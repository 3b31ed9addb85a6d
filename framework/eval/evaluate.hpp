#pragma once
/// \file
/// Building a `metrics:` list and averaging per-character values over a split, for the trainer
/// and the evaluator:
///
///     const auto metrics = eval::make_metrics(config.root()["metrics"]);
///     std::vector<std::map<std::string, double>> rows;
///     for (each test character c) {
///       std::map<std::string, double> row;
///       for (const auto& m : metrics) row.merge((*m)({pred, target, &c}));
///       rows.push_back(row);
///     }
///     const auto table_row = eval::mean_over_characters(rows);  // Table 3: mean per metric
///
/// Per-character values are the metrics' own (each averages within the character as its header
/// says); characters then count equally (the RigNet-lineage convention, HeterSkinNet Sec. 4.5:
/// "metrics are averaged over the whole test set").

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/eval/metric.hpp"

namespace skinlab::eval {

/// Builds every entry {type: key, ...options} of a non-empty `metrics:` list through
/// metric_registry(), in list order. Throws ConfigError (with the file, line and key path) for a
/// node that is not a non-empty list and for two entries reporting the same output name (both
/// entries and the name are given); RegistryError for an unknown type; the metric's own
/// ConfigError for a bad option.
std::vector<std::shared_ptr<Metric>> make_metrics(const config::Node& list);

/// The mean of every named value over the characters (one map per character). Every map must
/// carry the same names: otherwise throws Error naming the first character whose names differ
/// from the first character's, with both name lists. An empty input gives an empty map. A NaN
/// value (a metric undefined for that character, e.g. dominant_joint's `leaf_to_parent` for a
/// character without leaf-dominated vertices) is left out of its mean; a value NaN for every
/// character has a NaN mean.
std::map<std::string, double> mean_over_characters(
    const std::vector<std::map<std::string, double>>& per_character);

}  // namespace skinlab::eval

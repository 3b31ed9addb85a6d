#pragma once
/// \file
/// Interface of the `metric` registry: one character's predicted bone weights against its
/// ground truth (HeterSkinNet Sec. 4.3). A metric returns one or more named numbers for one
/// character; the evaluator averages each over the characters of a split (the RigNet-lineage
/// convention) and writes them to the run's metrics.
///
///     metrics:
///       - {type: precision_recall, threshold: 1.0e-4, prune: 0.25}
///       - {type: avg_l1}
///       - {type: deformation_error, poses: 10}
///
/// Registered metrics (each documented in its own header, with its thresholds):
/// precision_recall.hpp, avg_l1.hpp, deformation_error.hpp; evaluate.hpp builds the list and
/// averages over characters.

#include <torch/torch.h>

#include <map>
#include <string>
#include <vector>

#include "framework/data/dataset_file.hpp"

namespace skinlab::eval {

struct MetricInputs {
  torch::Tensor pred;    ///< #V×#B float32 predicted bone weights, rows sum to 1
  torch::Tensor target;  ///< #V×#B float32 ground-truth bone weights, rows sum to 1
  /// The prepared character (skeleton, bones, mesh) in the normalised 1 m frame, for metrics
  /// that deform the mesh. Bone b of `pred` is row b of `character->bones`.
  const data::PreparedCharacter* character = nullptr;
};

class Metric {
 public:
  virtual ~Metric() = default;
  /// Named values for one character, e.g. {"precision": 0.8, "recall": 0.7}. Names are unique
  /// across the registered metrics so the evaluator can merge them.
  virtual std::map<std::string, double> operator()(const MetricInputs& in) const = 0;
  /// The names operator() returns, known before any character is evaluated, so a `metrics:`
  /// list with two metrics reporting the same name is rejected when it is built (evaluate.hpp)
  /// and a table knows its columns.
  virtual std::vector<std::string> names() const = 0;
};

}  // namespace skinlab::eval

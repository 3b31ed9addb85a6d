#pragma once
/// \file
/// What a predicting program runs: a loaded model that turns a character into a Prediction
/// (infer/prediction.hpp), libtorch's (predict/predictor.hpp, `skinlab predict`) or Eigen's
/// (infer/eigen_predictor.hpp, `skinlab-predict`), behind the shared command line
/// (infer/predict_command.hpp).

#include <string>

#include "framework/infer/prediction.hpp"

namespace skinlab::infer {

/// A loaded model that predicts weights for a character (steps 1–4 of infer/prediction.hpp).
class PredictEngine {
 public:
  virtual ~PredictEngine() = default;
  /// Predicts weights for `character` (mesh and skeleton in its own frame; its weights, if any,
  /// are ignored for the prediction and kept in `prepared` for comparison). `times`, if given,
  /// receives normalise/distance/graph/network/map_back.
  virtual Prediction predict(const geometry::Character& character,
                             const PredictOptions& options = {},
                             StageTimes* times = nullptr) const = 0;
  /// "results/bundled/heterskinnet (model.pt, epoch 35)" and the like, for logs and .h5 files.
  virtual const std::string& description() const = 0;
  /// The distance registry key the model reads.
  virtual const std::string& distance() const = 0;
};

}  // namespace skinlab::infer

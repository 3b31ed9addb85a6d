#pragma once
/// \file
/// Skin weights for any character with a trained model (`skinlab predict`): the whole pipeline
/// of training data preparation (data/preprocess.hpp: normalise, merge, subdivide, distance,
/// top-K, graph) run on the fly on one character, the network in eval mode, and the weights
/// mapped back to the character's own vertices and joints in its own frame.
///
/// A model is a directory:
///   - a run directory of `skinlab train` (config.yaml, best.pt / last.pt); the preprocessing
///     is the one its dataset was prepared with (the `preparation` attribute of the run's
///     `data.file`, data/dataset_file.hpp), so the dataset file must still exist; or
///   - a bundled model (`skinlab bundle`, results/bundled/<name>/): config.yaml, model.pt
///     (parameters only), parameters.h5 (the same, for `skinlab-predict`) and
///     preparation.yaml, self-contained (infer/model_dir.hpp).
///
/// Everything but the forward pass is torch-free and shared with `skinlab-predict`, whose
/// network is Eigen (infer/prediction.hpp, infer/network.hpp).

#include <torch/torch.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/data/dataset_file.hpp"
#include "framework/data/preprocess.hpp"
#include "framework/geometry/skin_weights.hpp"
#include "framework/infer/engine.hpp"
#include "framework/infer/prediction.hpp"
#include "framework/train/run_options.hpp"

namespace skinlab::models {
class Model;
}
namespace skinlab::eval {
class Metric;
}

namespace skinlab::predict {

// What a prediction is, and everything around the forward pass (checks, preprocessing,
// candidates, pruning, mapping back), is torch-free and shared with `skinlab-predict`
// (infer/prediction.hpp); so is the command line (infer/predict_command.hpp).
using infer::check_predictable;
using infer::Prediction;
using infer::PredictOptions;
using infer::StageTimes;

/// The libtorch forward pass of a trained model.
class Predictor final : public infer::PredictEngine {
 public:
  /// Loads the model in `dir` (see the file comment). Throws IoError/ConfigError naming the
  /// file for a directory that is neither kind, a missing checkpoint or preparation, a
  /// checkpoint that does not fit the config's model, and a config with a binder (not learned).
  static Predictor load(const std::filesystem::path& dir, const std::string& checkpoint = "best");

  /// Predicts weights for `character` (mesh and skeleton in its own frame; its weights, if any,
  /// are ignored for the prediction and kept in `prepared` for comparison). `times`, if given,
  /// receives normalise/distance/graph/network/map_back. Throws GeometryError/Error naming the
  /// character and the element for anything the pipeline cannot handle.
  Prediction predict(const geometry::Character& character, const PredictOptions& options = {},
                     StageTimes* times = nullptr) const override;

  /// The metrics of the model's config (`metrics:`) of `p` against the weights the input
  /// carried (HeterSkinNet Sec. 4.3), on every joint of the input's skeleton (a preparation's
  /// drop_weightless_leaves does not apply to predictions; to score as `eval` does on a dataset
  /// that drops them, score p.joint_weights with score()). Throws Error when the input had no
  /// weights.
  std::map<std::string, double> compare(const Prediction& p) const;

  /// The metrics of the model's config of another method's per-joint weights `other` (#V×#J of
  /// `truth`'s mesh and skeleton, e.g. Blender's automatic weights) against `truth`'s own
  /// weights, both prepared exactly as a prediction's (merged, subdivided, bone-level rule with
  /// the model's distance). Throws Error naming the character when `truth` has no weights or
  /// `other` has another shape.
  std::map<std::string, double> score(const geometry::Character& truth,
                                      const geometry::SparseWeights& other,
                                      const PredictOptions& options = {}) const;

  /// Writes the model's parameters and architecture in the plain format of
  /// infer/parameters.hpp (what `skinlab-predict` runs), atomically.
  void write_parameters(const std::filesystem::path& file) const;

  const train::RunOptions& run_options() const { return options_; }
  const std::string& distance() const override { return options_.data.distance; }
  /// "results/heterskinnet/full-20261201 (best, epoch 35)" and the like, for logs.
  const std::string& description() const override { return description_; }

 private:
  Predictor() = default;
  /// The config's metrics of `pred` against `target` (#V×#B each) on `character`.
  std::map<std::string, double> metrics_of(const torch::Tensor& pred, const torch::Tensor& target,
                                           const data::PreparedCharacter& character) const;
  train::RunOptions options_;
  std::shared_ptr<models::Model> model_;
  infer::Preparation preparation_;  ///< the preprocessing and the one distance the model reads
  std::vector<std::shared_ptr<eval::Metric>> metrics_;
  std::string description_;
  /// What predictions do with the model's prior after the network (infer::use_prior)
  infer::PriorUse prior_use_;
};

/// Makes the bundled model `out` (a new directory) from the run `run_dir` and its checkpoint
/// `checkpoint` (best or last): config.yaml, preparation.yaml, model.pt (the parameters only,
/// no optimizer state: a third of a training checkpoint), parameters.h5 (the same parameters
/// in the plain format of infer/parameters.hpp, for `skinlab-predict`), and the run's env.json,
/// metrics.jsonl and eval_*.json/csv for provenance. The directory is assembled beside `out` and
/// renamed into place; an existing `out` is an error (nothing is overwritten).
void bundle(const std::filesystem::path& run_dir, const std::filesystem::path& out,
            const std::string& checkpoint = "best");

}  // namespace skinlab::predict

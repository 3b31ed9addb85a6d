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
///     (parameters only) and preparation.yaml, self-contained.
///
/// Every vertex gets weights. The distances assign every vertex a finite distance to every
/// bone (HollowDist restarts its search for parts the first search does not reach, HeterSkinNet
/// Alg. 1; the other distances have their own rules), so every vertex has K candidates; a
/// vertex whose candidate distances are not finite is an error naming the vertex, never a
/// silent zero row.

#include <torch/torch.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/data/dataset_file.hpp"
#include "framework/data/preprocess.hpp"
#include "framework/geometry/skin_weights.hpp"
#include "framework/train/run_options.hpp"

namespace skinlab::models {
class Model;
}
namespace skinlab::eval {
class Metric;
}

namespace skinlab::predict {

/// Wall-clock seconds of the stages of one prediction (the benchmark's and `--timings`' rows).
struct StageTimes {
  double load = 0;       ///< reading the input file(s) and validating them
  double normalise = 0;  ///< normalise, merge co-located vertices, subdivide
  double distance = 0;   ///< vertex–bone distances and top-K candidates
  double graph = 0;      ///< one-ring and geodesic edges
  double network = 0;    ///< tensors, forward pass, scatter and pruning
  double map_back = 0;   ///< weights at the input's vertices and joints
  double export_ = 0;    ///< writing the output file(s)
  double total() const {
    return load + normalise + distance + graph + network + map_back + export_;
  }
};

struct PredictOptions {
  /// Weights below this fraction of their row's maximum are dropped and the row renormalised
  /// (HeterSkinNet Sec. 4.5's 0.25, the post-processing every compared method gets); 0 keeps
  /// the network's raw distribution.
  double prune = 0.25;
  /// The input's up direction, rotated to +Y by the normalisation (geometry/normalize.hpp).
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  /// Inputs with more vertices are refused: the network's memory grows linearly with #V (the
  /// paper's characters have 1K–5K vertices; predict_bench measures the peak at 5K).
  int max_vertices = 50000;
  /// A joint farther than this fraction of the mesh's bounding-box diagonal outside that box is
  /// an error: the rig and the mesh do not belong together (other units or another frame).
  double max_joint_outside = 0.5;
};

/// Throws Error naming the character and the element when `character` cannot be predicted
/// for: more than `options.max_vertices` vertices, a joint outside the mesh (see
/// PredictOptions::max_joint_outside), or a skeleton of two or more joints that all sit at one
/// point (every bone has zero length, so no bone has a direction to skin along). Mesh and
/// skeleton validity (finite, in range, acyclic, one root) are checked when they are loaded.
void check_predictable(const geometry::Character& character, const PredictOptions& options);

struct Prediction {
  data::PreparedCharacter prepared;      ///< normalised, merged, subdivided; weights if given
  data::RowMatrixXf candidates;          ///< #V×K network output over prepared.topk_index
  data::RowMatrixXf prepared_weights;    ///< #V×#B at the prepared vertices, pruned
  data::RowMatrixXf source_weights;      ///< #V_in×#B at the input's vertices, pruned
  geometry::SparseWeights joint_weights; ///< #V_in×#J per-joint weights at the input's vertices
  /// #V×#B ground-truth bone weights at the prepared vertices when the input carried weights
  /// (the bone-level rule of data/preprocess.hpp with the model's distance); 0×0 otherwise
  data::RowMatrixXf prepared_truth;
};

class Predictor {
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
                     StageTimes* times = nullptr) const;

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

  const train::RunOptions& run_options() const { return options_; }
  const std::string& distance() const { return options_.data.distance; }
  /// "results/heterskinnet/full-20261201 (best, epoch 35)" and the like, for logs.
  const std::string& description() const { return description_; }

 private:
  Predictor() = default;
  /// The config's metrics of `pred` against `target` (#V×#B each) on `character`.
  std::map<std::string, double> metrics_of(const torch::Tensor& pred, const torch::Tensor& target,
                                           const data::PreparedCharacter& character) const;
  train::RunOptions options_;
  std::shared_ptr<models::Model> model_;
  std::vector<data::NamedDistance> distances_;  ///< the one the model reads
  data::PreprocessOptions preprocess_;
  std::vector<std::shared_ptr<eval::Metric>> metrics_;
  std::string description_;
};

/// Makes the bundled model `out` (a new directory) from the run `run_dir` and its checkpoint
/// `checkpoint` (best or last): config.yaml, preparation.yaml, model.pt (the parameters only,
/// no optimizer state: a third of a training checkpoint), and the run's env.json,
/// metrics.jsonl and eval_*.json/csv for provenance. The directory is assembled beside `out` and
/// renamed into place; an existing `out` is an error (nothing is overwritten).
void bundle(const std::filesystem::path& run_dir, const std::filesystem::path& out,
            const std::string& checkpoint = "best");

/// `dir`'s preparation YAML ("preprocess: ...\ndistances: [...]"): `<dir>/preparation.yaml`, or
/// the `preparation` attribute of the dataset file named by the run's `data.file`.
std::string read_preparation(const std::filesystem::path& dir, const train::RunOptions& run);

}  // namespace skinlab::predict

#pragma once
/// \file
/// Training and evaluation of the corrective-deformation task (`task: corrective`; DenseGATs,
/// Li et al. I3D 2020, Sec. 3.4 and 4), on the data of corrective_data.hpp.
///
/// Training (Sec. 3.4): Adam (`train.lr`, 1e-3 in the paper), the config's `losses:` (`mse` on
/// the displacement in cm), `corrective.batch_size` samples per step (8) with their losses
/// averaged, each sample a (train character, pose) pair drawn at random with a window of
/// `corrective.window` consecutive vertices (Sec. 4: "one thousand consecutive vertices from
/// each character mesh"; the network runs on the window's one-ring subgraph), and the learning
/// rate multiplied by `plateau.factor` (0.75) when the validation loss has not improved for more
/// than `plateau.patience` (8) epochs, down to `plateau.min_lr` (5e-7), as PyTorch's
/// ReduceLROnPlateau does. An epoch is `corrective.samples_per_epoch` samples. Validation: the
/// mean loss over the val characters at `eval_poses` evenly spaced poses each, on whole meshes in
/// eval mode. Checkpoints, metrics.jsonl, resuming (the plateau state included) and early
/// stopping (`train.patience`) work as for the skinning Trainer (trainer.hpp).
///
/// Evaluation (Sec. 4.1, Table 3): on every character of a part, at `eval_poses` evenly spaced
/// poses, the distance |LBS + prediction − target| of every vertex in cm at the character's
/// height; per character the mean, max and min over its vertices and poses (`mean_error_cm`,
/// `max_error_cm`, `min_error_cm`), written as eval_<part>.json/.csv like every evaluation, so
/// `skinlab table --metrics mean_error_cm,max_error_cm,min_error_cm` builds Table 3. A config
/// with `corrective.baseline: lbs` (no correction) or `dqs` (dual quaternion skinning with the
/// same weights instead of LBS; Sec. 4.2, Fig. 10) and no model is evaluated the same way.

#include <memory>
#include <string>
#include <vector>

#include "experiments/densegats/corrective_data.hpp"
#include "framework/core/config.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/eval/evaluator.hpp"
#include "framework/graph/graph_op.hpp"
#include "framework/losses/loss.hpp"
#include "framework/models/corrective_model.hpp"
#include "framework/train/run_data.hpp"
#include "framework/train/run_options.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::densegats {

/// The one-ring graph of a character (vertex nodes only).
graph::Graph mesh_graph(const CorrectiveCharacter& character);

/// `count` of the indices [0, n), evenly spaced (k·n/count; all of them when n ≤ count).
std::vector<int> evenly_spaced(std::size_t n, int count);

/// `count` pose indices of `character`, evenly spaced over its pose list (all when it has fewer).
std::vector<int> eval_pose_indices(const CorrectiveCharacter& character, int count);

/// The rows [first, first + count) of a sample and the subgraph of the mesh edges between them
/// (renumbered from 0): what one training step sees.
struct Window {
  torch::Tensor features, target;
  graph::Graph graph;
};
Window window_of(const CorrectiveSample& sample, const torch::Tensor& one_ring,
                 std::int64_t first, std::int64_t count);

/// A validated corrective config: the run options and the `corrective:` section.
struct CorrectiveConfig {
  train::RunOptions run;
  CorrectiveOptions corrective;
  /// Throws ConfigError / RegistryError naming the file, line and key for anything invalid,
  /// including a config whose task is not `corrective`.
  static CorrectiveConfig from(const config::Config& config);
};

class CorrectiveTrainer {
 public:
  /// Validates `config` (a model, losses, data, no baseline), reads the dataset and split,
  /// builds the task's data, seeds libtorch and builds the model (checking its input width
  /// against the data's), the loss and the optimizer. Nothing is written.
  explicit CorrectiveTrainer(const config::Config& config);
  /// Trains in `run` (resuming from its last.pt), as Trainer::fit.
  train::TrainResult fit(const RunDir& run, const train::FitLimits& limits = {});
  /// Mean validation loss (eval mode, whole meshes, the fixed validation poses); NaN without
  /// validation characters.
  double validation_loss();
  bool has_validation() const { return !validation_.empty(); }
  models::CorrectiveModel& model() { return *model_; }
  const CorrectiveData& data() const { return *data_; }

 private:
  double step(const std::vector<std::pair<int, int>>& batch, at::Generator& rng);
  double loss_of(const torch::Tensor& pred, const torch::Tensor& target,
                 std::map<std::string, double>* parts = nullptr) const;
  torch::Tensor loss_tensor(const torch::Tensor& pred, const torch::Tensor& target,
                            std::map<std::string, double>* parts) const;

  config::Config config_;
  CorrectiveConfig options_;
  train::RunData run_data_;
  std::unique_ptr<CorrectiveData> data_;
  std::vector<int> train_, val_;
  struct Cached {
    torch::Tensor features, target;
    graph::Graph graph;
  };
  std::vector<Cached> validation_;
  std::shared_ptr<models::CorrectiveModel> model_;
  losses::LossSum loss_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
  torch::Tensor initial_torch_rng_;
  bool fitted_ = false;
};

/// Evaluates a corrective run (a trained model's checkpoint, or a baseline config's deformer)
/// on one part; see the file comment. Throws as eval::evaluate.
eval::EvalReport evaluate_corrective(const RunDir& run, const eval::EvalOptions& options);

}  // namespace skinlab::densegats

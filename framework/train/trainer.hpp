#pragma once
/// \file
/// Training as HeterSkinNet Sec. 4.2: Adam (lr 1e-4, weight decay 1e-4 from `train:`), one
/// character per step, epochs over the train part of the configured split in a seeded shuffled
/// order, the loss on the validation part after every epoch, early stopping on it, and per epoch
/// a line in the run's metrics.jsonl and the checkpoints `last.pt` and (when the validation loss
/// improved) `best.pt` (checkpoint.hpp).
///
/// The loss (the config's `losses:` weighted sum) is evaluated in bone space: the model's #V×K
/// distribution and the #V×K target are both scattered to #V×#B (data::scatter_to_bones), so the
/// Laplacian smoothing term is Σ_j w_jᵀ L w_j over the bone columns w_j as Eq. 6 writes it (on the
/// K candidate columns it would mix different bones of neighbouring vertices); the data terms
/// are unchanged by the scatter because the target is zero off the candidates.
///
/// Determinism: libtorch's CPU generator is seeded with the config's `seed` before the model is
/// built (initialisation, dropout), and the training order comes from a second generator seeded
/// from it, so two runs with the same config and thread count give identical weights. Resuming
/// restores parameters, optimizer state, both generators and the early-stopping state from
/// `last.pt`, so an interrupted run continues to the same result as an uninterrupted one.
///
/// Without a validation part (an empty `val` list) the train loss selects `best.pt` and drives
/// early stopping, with a warning.
///
/// Batches: a step averages the gradients of `train.batch` consecutive characters of the epoch's
/// order (1 in the paper). Data parallelism (distributed.hpp): in a world of N processes every
/// process draws the same order, a step covers the next N × batch characters and process r
/// takes every N-th of them from the r-th; the gradients are summed over the world and divided
/// by the step's character count, so every process takes the same Adam step. Rank 0 broadcasts
/// the initial (or resumed) parameters first and is the only one to write metrics and
/// checkpoints; the validation loss is computed on every N-th character per process and summed.
/// A run of N processes with batch b therefore follows a one-process run with batch N·b up to
/// floating-point summation order, for models whose training draws no random numbers (with
/// dropout each process draws its own masks).

#include <memory>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/losses/loss.hpp"
#include "framework/models/model.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/distributed.hpp"
#include "framework/train/run_data.hpp"
#include "framework/train/run_options.hpp"

namespace skinlab::train {

inline constexpr const char* kLastCheckpoint = "last.pt";
inline constexpr const char* kBestCheckpoint = "best.pt";

struct TrainResult {
  int epochs = 0;            ///< completed epochs of the run, over every session
  int epochs_this_call = 0;  ///< epochs trained by this call
  int best_epoch = 0;        ///< epoch saved as best.pt
  double best_loss = 0;      ///< its selection loss (validation loss; train loss without val)
  bool resumed = false;      ///< continued from last.pt
  bool early_stopped = false;
  bool interrupted = false;  ///< returned because of FitLimits::stop_after_epochs
  double seconds = 0;        ///< wall time of this call
};

struct FitLimits {
  /// Return after this many epochs of this call, as a killed process would stop after writing
  /// its checkpoint (tests of resuming); 0 = no limit.
  int stop_after_epochs = 0;
};

/// Builds through the registries (`model`, `loss`), given the config's seed.
std::shared_ptr<models::Model> build_model(const RunOptions& options);

class Trainer {
 public:
  /// Validates `config` (RunOptions, and that model, losses and data are there), reads the
  /// dataset and the split, converts the train and val characters, seeds libtorch and builds the
  /// model, the loss and the optimizer. Throws ConfigError / IoError / RegistryError before any
  /// file is written: an empty train part, a model without parameters and a character lacking
  /// the distance type are errors here.
  ///
  /// `world`: the processes this one trains with (nullptr: alone); it must outlive the Trainer.
  explicit Trainer(const config::Config& config, World* world = nullptr);

  /// Trains in `run` until `train.epochs` epochs or early stopping. If `run` has a `last.pt`,
  /// continues from it (records of later epochs in metrics.jsonl, written by a process killed
  /// before its checkpoint, are dropped first). Call once per Trainer.
  TrainResult fit(const RunDir& run, const FitLimits& limits = {});

  const RunOptions& options() const { return options_; }
  models::Model& model() { return *model_; }
  RunData& data() { return data_; }
  const RunData& data() const { return data_; }

  /// Mean loss over `part` ("train", "val", "test") in eval mode without gradients; `parts`
  /// receives each term's mean.
  double mean_loss(const std::string& part, std::map<std::string, double>* parts = nullptr);

 private:
  /// One optimiser step over `indices` (this process's share of the step) when the whole step
  /// covers `step_characters` characters; returns this process's loss sum.
  double step(const std::vector<int>& indices, std::size_t step_characters,
              std::map<std::string, double>& parts);
  /// The loss terms' names, in a fixed order (for sums over the world).
  std::vector<std::string> part_names() const;
  /// `value` summed over the world; `parts` likewise, by part_names().
  double world_sum(double value, std::map<std::string, double>& parts);
  torch::Tensor loss_of(const data::CharacterTensors& c, const torch::Tensor& pred,
                        std::map<std::string, double>* parts) const;

  config::Config config_;
  RunOptions options_;
  RunData data_;
  World* world_ = nullptr;
  std::unique_ptr<World> alone_;  ///< the world of one when none is given
  std::shared_ptr<models::Model> model_;
  losses::LossSum loss_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
  torch::Tensor initial_torch_rng_;  ///< libtorch's generator right after the model was built
  bool fitted_ = false;
};

/// Creates `<results_dir>/<experiment>/<run_id>/` (run_id "" → a UTC time stamp) with the
/// resolved `config.yaml` and `env.json` (seed, threads in effect, `command`).
RunDir create_run(const config::Config& config, const RunOptions& options,
                  const std::string& run_id, const std::vector<std::string>& command);

/// Checks that `prediction` is #V×K for `c`; throws Error naming the model type and character.
void check_prediction(const torch::Tensor& prediction, const data::CharacterTensors& c,
                      const RunOptions& options);

/// What the run's losses see for `c`: the prediction `weights` (#V×#B, see
/// data::scatter_to_bones), the targets and the named `priors` of `c` laid out the same way
/// (the losses' LossSum::priors; only those, as the layout costs a #V×#B tensor each), and the
/// mesh Laplacian. Shared by training and evaluation so both score the same terms. Throws Error
/// naming the character when it lacks one of `priors` (data::prior_of).
losses::LossInputs loss_inputs(const data::CharacterTensors& c, const torch::Tensor& weights,
                               const std::vector<std::string>& priors);

}  // namespace skinlab::train

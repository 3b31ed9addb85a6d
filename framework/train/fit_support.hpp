#pragma once
/// \file
/// What every training loop of the framework shares (the skinning Trainer, trainer.hpp, and the
/// corrective-deformation task, experiments/densegats): generator state for checkpoints, the
/// training order's own seed, progress text, and cleaning up after a killed process, so that
/// resuming means the same thing in every task.

#include <ATen/core/Generator.h>
#include <torch/torch.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "framework/core/run_dir.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/run_options.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::train {

/// A copy of `generator`'s state (under its lock), for a checkpoint.
torch::Tensor get_rng_state(at::Generator generator);
/// Restores a state from get_rng_state.
void set_rng_state(at::Generator& generator, const torch::Tensor& state);

/// Seed of the training order's generator: its own stream, so a model that draws more or fewer
/// random numbers (dropout on or off) still sees the data in the same order.
std::uint64_t order_seed(std::int64_t seed);

/// "h:mm:ss".
std::string duration(double seconds);
/// "kl 0.1, laplacian_smoothing 0.02": a loss's parts for a log line.
std::string parts_text(const std::map<std::string, double>& parts);
/// The same as a JSON object, for metrics.jsonl.
nlohmann::json parts_json(const std::map<std::string, double>& parts);

/// Removes files a killed process left while writing `last.pt`, `best.pt` or `metrics.jsonl`
/// (AtomicPath's `.<name>.tmp-<pid>-<n>`).
void remove_stale_temporaries(const RunDir& run);

/// Keeps the metrics.jsonl records of epochs ≤ `epoch` (a killed run may have logged an epoch
/// whose checkpoint it never wrote; that epoch is trained again).
void truncate_metrics(const RunDir& run, std::int64_t epoch);

/// Records that epoch `epoch` ended with selection loss `selection` (validation loss, or the
/// train loss without validation): sets state.epoch and, when it improved (finite, and the first
/// or below best_loss − min_delta), best_epoch and best_loss. Returns whether it improved.
bool record_epoch(TrainingState& state, std::int64_t epoch, double selection, double min_delta);

/// Whether `state` ends a fit early: patience > 0 and no improvement for `patience` epochs after
/// the best one.
bool stopped_early(const TrainingState& state, const TrainOptions& options);
/// Whether a run in `state` has nothing left to train: all `options.epochs` done, or stopped early.
bool finished(const TrainingState& state, const TrainOptions& options);

/// How a fit starts (`start_fit`): the state to continue from, and whether it came from last.pt.
struct FitStart {
  TrainingState state;  ///< epoch and best counters restored; seed, threads, model config set
  bool resumed = false;
  std::map<std::string, double> extra;  ///< the checkpoint's task state (empty when starting)
};

/// The start of every fit in `run`: removes a killed process's temporaries; when `run` has
/// last.pt, loads it into `model` and `optimizer` (Error for another seed than `seed`, a warning
/// for another thread count), restores both generators and the epoch and best counters and logs
/// it; otherwise resets `torch_rng` to `initial_torch_rng`. Then drops metrics.jsonl records past
/// the restored epoch. A resume is recorded in env.json only when `options` leave epochs to
/// train: opening a finished run (a sweep run again) changes none of its files. A process that
/// does not write the run (`writer` false: ranks other than 0 of a distributed run) only reads:
/// it neither removes temporaries nor truncates metrics.
FitStart start_fit(const RunDir& run, torch::nn::Module& model, torch::optim::Optimizer& optimizer,
                   std::int64_t seed, const TrainOptions& options, const std::string& model_config,
                   at::Generator& torch_rng,
                   at::Generator& order_rng, const torch::Tensor& initial_torch_rng,
                   bool writer = true);

/// The end of a fit: sets `result`'s early_stopped (stopped_early before `options.epochs`;
/// logged unless the fit was interrupted), epochs, best epoch and loss from the final `state`,
/// and the wall time since `start`.
void finish_fit(TrainResult& result, const TrainingState& state, const TrainOptions& options,
                std::chrono::steady_clock::time_point start);

}  // namespace skinlab::train

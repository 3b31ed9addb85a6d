#pragma once
/// \file
/// Training checkpoints (`best.pt`, `last.pt` in a run directory): a libtorch archive holding the
/// model's parameters and buffers, the optimizer state, the epoch, both RNG states and the
/// early-stopping state, so that a resumed run continues exactly where the checkpoint was taken
/// (bit-identical on the CPU with the same thread count).
///
/// Files are written through a temporary file in the same directory and renamed into place
/// (atomic_file.hpp): a crash while saving leaves the previous checkpoint, never a partial one.
/// Loading checks every parameter's name and shape against the model before copying anything,
/// so a checkpoint of another architecture or size is an error naming the first difference.

#include <torch/torch.h>

#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <string>

namespace skinlab::train {

/// Version of the checkpoint layout; another version is rejected.
inline constexpr std::int64_t kCheckpointVersion = 1;

/// Everything but the tensors of model and optimizer.
struct TrainingState {
  std::int64_t epoch = 0;       ///< completed epochs
  std::int64_t best_epoch = 0;  ///< epoch of the best selection loss so far (0: none yet)
  double best_loss = std::numeric_limits<double>::infinity();  ///< its selection loss
  std::int64_t seed = 0;
  std::int64_t threads = 0;      ///< libtorch threads the run used (determinism needs the same)
  torch::Tensor torch_rng;       ///< state of libtorch's default CPU generator (dropout etc.)
  torch::Tensor order_rng;       ///< state of the generator of the training order
  std::string model_config;      ///< the `model:` section as YAML, for messages
  /// A task's own scalar state (e.g. the corrective task's learning-rate plateau counter);
  /// empty for the skinning Trainer. Absent from a checkpoint written without it.
  std::map<std::string, double> extra;
};

/// "name [d0, d1, ...]" of every parameter and buffer of `model`, one per line, in the module's
/// order: what a checkpoint must match.
std::string parameter_spec(const torch::nn::Module& model);

/// Throws Error naming the parameter when a submodule name is a Python keyword (`in`, `def`,
/// ...): libtorch stores archives as TorchScript, whose reader rejects such names, so the
/// checkpoint would be written but could never be read back. The Trainer checks this up front.
void check_checkpointable(const torch::nn::Module& model);

/// `run_dir`/best.pt or `run_dir`/last.pt for `which` = "best" or "last" (whether it exists is
/// the caller's question). Throws Error for any other name.
std::filesystem::path checkpoint_file(const std::filesystem::path& run_dir,
                                      const std::string& which);

/// checkpoint_file, and it must exist: IoError "<path>: no checkpoint '<which>' in this run ..."
/// otherwise (what evaluating or generating from a run needs).
std::filesystem::path existing_checkpoint(const std::filesystem::path& run_dir,
                                          const std::string& which);

/// Writes `path` atomically. `optimizer` may be null (then no optimizer state is stored).
void save_checkpoint(const std::filesystem::path& path, const torch::nn::Module& model,
                     const torch::optim::Optimizer* optimizer, const TrainingState& state);

/// Reads `path` into `model` (and `optimizer` when given, which must have been built over
/// `model`'s parameters) and returns the rest. Throws IoError naming the file for a missing or
/// unreadable file, another layout version, a checkpoint without optimizer state when one is
/// asked for, and a model whose parameters differ from the checkpoint's (the first missing,
/// unexpected or differently shaped parameter is named, with the checkpoint's model config).
TrainingState load_checkpoint(const std::filesystem::path& path, torch::nn::Module& model,
                              torch::optim::Optimizer* optimizer = nullptr);

}  // namespace skinlab::train

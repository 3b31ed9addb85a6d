#pragma once
/// \file
/// The top level of an experiment config. Every key a config may have at the top level is read
/// here; plug-in sections are validated by constructing them through their registries, so a
/// misspelled option or unknown `type:` anywhere is reported before any work starts.
///
///     experiment: heterskinnet        # results go to <results_dir>/<experiment>/<run_id>/
///     task: skinning                  # or corrective: DenseGATs' task (experiments/densegats),
///                                     # whose model is a `corrective_model` and which reads a
///                                     # `corrective:` section (validated by that task);
///                                     # or sequence: the mesh-sequence BiLSTM
///                                     # (experiments/bdlstm), with a `sequences:` section
///     description: ...                # free text, saved with the run
///     seed: 0                         # every random choice of the run derives from it
///     threads: 0                      # libtorch intra-op threads; 0 = every hardware thread
///     results_dir: results
///     model: {type: ...}              # `model` registry (a network, trained by `skinlab train`)
///     binder: {type: ...}             # or: `binder` registry (not learned; `skinlab eval <config>`)
///     losses: [{type: kl, weight: 1}] # `loss` registry, weighted sum
///     metrics: [{type: ...}]          # `metric` registry
///     data:                           # what `skinlab train` / `skinlab eval` read
///       file: results/datasets/zeroad.h5  # a prepared dataset (skinlab prepare)
///       split: random                 # a split of that file: /splits/<split>/{train,val,test}
///       distance: hollow_dist         # distance type of the top-K candidates and 1/D inputs
///     train:                          # HeterSkinNet Sec. 4.2
///       epochs: 100
///       lr: 1.0e-4                    # Adam
///       weight_decay: 1.0e-4
///       patience: 10                  # early stopping on the validation loss; 0 = off
///       min_delta: 0                  # an improvement smaller than this does not count
///       max_characters_per_epoch: 0   # 0 = the whole train split (smoke runs use a few)
///       log_every: 100                # a progress line every this many steps; 0 = per epoch
///
/// `data` and `train` are optional here so that `skinlab config` validates any experiment config;
/// `skinlab train` requires `model`, `losses` and `data`; evaluating a binder requires `binder`
/// and `data`. A config has a `model` or a `binder`, not both.

#include <cstdint>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "framework/core/config.hpp"

namespace skinlab::train {

/// The `data:` section.
struct DataOptions {
  std::string file;                   ///< dataset file (relative paths: to the working directory)
  std::string split = "random";       ///< name of a split stored in the file
  std::string distance = "hollow_dist";  ///< a `distance` registry key the file was prepared with
  /// Sources (their names in the dataset card) whose characters, with their variant groups,
  /// form the validation part instead of the split's own; the rest of the split's train and val
  /// parts trains (data::validate_on_sources). Empty: the split's parts as stored.
  std::vector<std::string> val_sources;

  /// Decodes and checks a `data:` map (`file` required; `distance` must be a registered
  /// distance type). Errors name the file, line and key.
  static DataOptions from(const config::Node& node);
};

/// The `train:` section (HeterSkinNet Sec. 4.2: Adam, lr 1e-4, weight decay 1e-4, one character
/// per step).
struct TrainOptions {
  int epochs = 100;
  double lr = 1e-4;
  double weight_decay = 1e-4;
  /// Stop when the validation loss has not improved (by more than `min_delta`) for this many
  /// epochs; 0 disables early stopping.
  int patience = 10;
  double min_delta = 0.0;
  /// Train on the first this many characters of each epoch's shuffled order; 0 = all.
  int max_characters_per_epoch = 0;
  /// Characters per optimiser step in each process: their gradients are averaged (HeterSkinNet
  /// trains with 1). With N processes (distributed.hpp) a step averages over N × batch.
  int batch = 1;
  /// A progress line (loss, rate, ETA) every this many steps; 0 = only the per-epoch line.
  int log_every = 100;

  /// Decodes and checks a `train:` map (every field optional). Errors name the file, line and key.
  static TrainOptions from(const config::Node& node);
};

struct RunOptions {
  std::string experiment;
  std::string description;
  std::int64_t seed = 0;
  int threads = 0;
  std::string results_dir = "results";
  std::string task = "skinning";  ///< a key of the task registry (framework/task/task.hpp)
  /// The section only the task reads, named by the task (`corrective:`, `sequences:`); missing
  /// when absent or when the task has none
  config::Node task_section;
  config::Node model;    ///< missing when the config has no model section
  config::Node binder;   ///< missing when the config has no binder section
  config::Node losses;   ///< missing when the config has no losses section
  config::Node metrics;  ///< missing when the config has no metrics section
  config::Node data_node;   ///< the `data:` section (missing when absent)
  DataOptions data;         ///< decoded `data:` (defaults when absent)
  TrainOptions train;       ///< decoded `train:` (defaults when absent)

  /// Reads and validates the whole config (see the file comment). Throws ConfigError or
  /// RegistryError with the file, line and key path of the first problem.
  static RunOptions from(const config::Config& config);

  /// Throws ConfigError naming the config file unless the sections training needs are present
  /// (the task says which: by default `model`, `losses` and `data`).
  void require_training_sections(const config::Config& config) const;
  /// Throws ConfigError naming the config file unless `binder` and `data` are present.
  void require_binder_sections(const config::Config& config) const;
};

/// Throws ConfigError naming the config file when one of `sections` (a node and an example of
/// it, e.g. "model: {type: ...}") is missing or null; `what` says what needs them.
void require_sections(const config::Config& config, const char* what,
                      std::initializer_list<std::pair<const config::Node*, const char*>> sections);
/// An example `data:` section, for such messages.
extern const char* const kDataExample;

}  // namespace skinlab::train

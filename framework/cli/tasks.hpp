#pragma once
/// \file
/// The task dispatch of the commands that train or evaluate (`train`, `eval`, `sweep`): a
/// config's `task:` (train/run_options.hpp) picks the skinning Trainer and evaluator, or the
/// corrective-deformation task's (experiments/densegats/corrective_task.hpp), or the mesh-sequence
/// task's (experiments/bdlstm/sequence_task.hpp).

#include <memory>

#include "experiments/bdlstm/sequence_task.hpp"
#include "experiments/densegats/corrective_task.hpp"
#include "framework/core/config.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/eval/evaluator.hpp"
#include "framework/report/table.hpp"
#include "framework/train/run_options.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::cli {

/// A method that is not trained: a skinning `binder`, or a corrective or sequence `baseline`. Checks that
/// the sections evaluating it needs are there (ConfigError otherwise).
bool untrained_method(const config::Config& config, const train::RunOptions& options);

/// The trainer of the config's task, built (and so validated) before any run directory exists.
class TaskTrainer {
 public:
  /// `world`: the processes of a data-parallel run (nullptr: this one alone); only the skinning
  /// task trains data-parallel, and only it has `train.batch` (Error otherwise).
  explicit TaskTrainer(const config::Config& config, train::World* world = nullptr);
  train::TrainResult fit(const RunDir& run, const train::FitLimits& limits = {});
  /// Whether the best checkpoint was selected on validation data (else the train loss).
  bool validated() const;

 private:
  std::unique_ptr<train::Trainer> skinning_;
  std::unique_ptr<densegats::CorrectiveTrainer> corrective_;
  std::unique_ptr<bdlstm::SequenceTrainer> sequence_;
};

/// The comparison table of evaluated runs: Qiao et al.'s Tables 1-2 for sequence runs
/// (experiments/bdlstm/sequence_table.hpp), report::make_table for the others.
std::string table_text(const std::vector<report::RunResult>& runs, const report::TableOptions& options);

/// Evaluates a run of any task (its config.yaml says which).
eval::EvalReport evaluate_run(const RunDir& run, const eval::EvalOptions& options);

}  // namespace skinlab::cli

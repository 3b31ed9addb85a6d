#pragma once
/// \file
/// The `task` registry: what a config's `task:` names. A task owns its config section, its
/// training, its evaluation, its comparison table, its figures and any command of its own, so
/// the framework and the command-line program never name an experiment. `skinning` (per-vertex
/// bone weights: HeterSkinNet and its baselines) is the framework's own task
/// (task/skinning_task.cpp); the papers' other tasks are plug-ins under experiments/ (DenseGATs'
/// `corrective`, the mesh-sequence BiLSTM's `sequence`). docs/plugins.md has the recipe.

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/eval/evaluator.hpp"
#include "framework/report/figure_options.hpp"
#include "framework/report/table.hpp"
#include "framework/train/run_options.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::task {

/// A task's trainer, built (and so validated) before any run directory exists.
class TaskTrainer {
 public:
  virtual ~TaskTrainer() = default;
  virtual train::TrainResult fit(const RunDir& run, const train::FitLimits& limits) = 0;
  /// Whether the best checkpoint was selected on validation data (else on the train loss).
  virtual bool validated() const = 0;
};

/// `skinlab figure`'s options; each task reads the ones it draws with.
using FigureOptions = report::FigureOptions;

/// An option of a task's own command: `--<name> <value>`.
struct CommandOption {
  std::string name;           ///< without the dashes
  std::string help;
  std::string default_value;  ///< shown in --help; empty: no default
  bool required = false;
};

/// A subcommand a task adds to `skinlab` (e.g. the sequence task's `generate`). It takes a run
/// directory of the task, `key=value` overrides of the run's config, and its options.
struct TaskCommand {
  std::string name;
  std::string help;
  std::vector<CommandOption> options;
  /// Runs it: the run directory (checked to be a run of this task), the overrides, and every
  /// option's value by name (its default when not given; absent when it has none).
  std::function<int(const RunDir& run, const std::vector<std::string>& overrides,
                    const std::map<std::string, std::string>& values)>
      run;
};

class Task {
 public:
  virtual ~Task() = default;

  /// Its registry key, e.g. "corrective".
  virtual std::string name() const = 0;
  /// The top-level config section only this task reads (e.g. "corrective"), empty for none.
  /// RunOptions keeps it in `task_section`; another task's config may not have it.
  virtual std::string section() const { return {}; }

  /// Checks a config's `model:` section: by default against the skinning `model` registry.
  virtual void check_model(const config::Node& model) const;
  /// Checks that a config has what training it needs (ConfigError naming the missing section).
  virtual void require_training_sections(const config::Config& config,
                                         const train::RunOptions& options) const;
  /// Validates every section the task reads (`skinlab config`); ConfigError on the first fault.
  virtual void validate(const config::Config& config) const;
  /// Whether the config's method is evaluated without training (a binder, a baseline); checks
  /// that the sections evaluating it needs are there.
  virtual bool untrained(const config::Config& config, const train::RunOptions& options) const;
  /// What an evaluated config of this task needs when it is not untrained (ConfigError).
  virtual void require_untrained_sections(const config::Config& config,
                                          const train::RunOptions& options) const;

  /// Whether it trains over several processes (`train --nproc`, `train.batch`) and evaluates
  /// sharded (`eval --nproc`).
  virtual bool data_parallel() const { return false; }
  /// Its trainer. `world` is non-null only for a data-parallel task.
  virtual std::unique_ptr<TaskTrainer> trainer(const config::Config& config,
                                               train::World* world) const = 0;
  /// Evaluates a run of this task.
  virtual eval::EvalReport evaluate(const RunDir& run, const eval::EvalOptions& options) const = 0;
  /// The comparison table of evaluated runs of this task (Markdown, or CSV per `options`).
  virtual std::string table(const std::vector<report::RunResult>& runs,
                            const report::TableOptions& options) const;
  /// `skinlab figure` on runs of this task (Error by default: no figures).
  virtual void figures(const FigureOptions& options) const;
  /// Its own subcommands.
  virtual std::vector<TaskCommand> commands() const { return {}; }
};

/// A task command's option value (TaskCommand::run's `values`) as an int, a double or a string;
/// Error naming `--name` when it is absent or does not parse whole.
int int_option(const std::map<std::string, std::string>& values, const std::string& name);
double double_option(const std::map<std::string, std::string>& values, const std::string& name);
/// ... or `fallback` when absent.
std::string string_option(const std::map<std::string, std::string>& values, const std::string& name,
                          const std::string& fallback = "");

/// The registered task `name`; RegistryError listing the known tasks otherwise.
const Task& get(const std::string& name);
/// Every registered task, by name.
std::vector<const Task*> all();
/// The task of a config (its `task:`, default skinning).
const Task& of(const config::Config& config);
/// The task of a run directory (its config.yaml's `task:`).
const Task& of_run(const RunDir& run);

/// The trainer of the config's task, built (and so validated) before any run directory exists.
/// `world`: the processes of a data-parallel run (nullptr: this one alone); Error when it has
/// several and the task does not train data-parallel, ConfigError for `train.batch` > 1 then.
std::unique_ptr<TaskTrainer> make_trainer(const config::Config& config,
                                          train::World* world = nullptr);
/// Error naming `source` unless the task trains data-parallel; `what` is what was asked for
/// ("data-parallel training (--nproc)") and `instead` what the task does ("trains in one process").
void require_data_parallel(const Task& task, const std::string& source, const std::string& what,
                           const std::string& instead);
/// Evaluates a run of any task (its config.yaml says which).
eval::EvalReport evaluate_run(const RunDir& run, const eval::EvalOptions& options);
/// The comparison table of evaluated runs, by the first run's task.
std::string table_text(const std::vector<report::RunResult>& runs,
                       const report::TableOptions& options);

}  // namespace skinlab::task

/// Registers task class `Class` (default-constructible) under `key`.
#define SKINLAB_REGISTER_TASK(key, Class)                                                      \
  static const auto SKINLAB_CONCAT(skinlab_registrar_, __COUNTER__) = ::skinlab::Registrar(    \
      ::skinlab::task_registry(), #key,                                                        \
      [](const ::skinlab::config::Node&) { return std::make_shared<Class>(); }, __FILE__,      \
      __LINE__)

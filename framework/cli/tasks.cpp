#include "framework/cli/tasks.hpp"

#include "experiments/bdlstm/sequence_table.hpp"
#include "framework/core/error.hpp"

namespace skinlab::cli {

bool untrained_method(const config::Config& config, const train::RunOptions& options) {
  if (options.task == "corrective") {
    return !densegats::CorrectiveConfig::from(config).corrective.baseline.empty();
  }
  if (options.task == "sequence") {
    return !bdlstm::SequenceConfig::from(config).sequences.baseline.empty();
  }
  if (options.binder.exists()) options.require_binder_sections(config);
  return options.binder.exists();
}

TaskTrainer::TaskTrainer(const config::Config& config, train::World* world) {
  const train::RunOptions options = train::RunOptions::from(config);
  const std::string& task = options.task;
  if (task != "skinning") {
    if (world != nullptr && world->distributed()) {
      throw Error(config.source() + ": data-parallel training (--nproc, WORLD_SIZE) is the "
                  "skinning task's; a " + task + " run trains in one process");
    }
    if (options.train.batch != 1) {
      throw ConfigError(config.source() + ": train.batch (characters per step) is the skinning "
                        "task's; the " + task + " task has its own batches");
    }
  }
  if (task == "corrective") {
    corrective_ = std::make_unique<densegats::CorrectiveTrainer>(config);
  } else if (task == "sequence") {
    sequence_ = std::make_unique<bdlstm::SequenceTrainer>(config);
  } else {
    skinning_ = std::make_unique<train::Trainer>(config, world);
  }
}

train::TrainResult TaskTrainer::fit(const RunDir& run, const train::FitLimits& limits) {
  if (corrective_) return corrective_->fit(run, limits);
  if (sequence_) return sequence_->fit(run, limits);
  return skinning_->fit(run, limits);
}

bool TaskTrainer::validated() const {
  if (corrective_) return corrective_->has_validation();
  if (sequence_) return false;  // the paper has no validation set; best.pt is by train loss
  return !skinning_->data().part("val").empty();
}

eval::EvalReport evaluate_run(const RunDir& run, const eval::EvalOptions& options) {
  const config::Config config = config::Config::load(run.file("config.yaml"), options.overrides);
  const std::string task = train::RunOptions::from(config).task;
  if (task != "skinning" && options.world != nullptr && options.world->distributed()) {
    throw Error(run.path().string() + ": sharded evaluation is the skinning task's; a " + task +
                " run is evaluated in one process");
  }
  if (task == "corrective") return densegats::evaluate_corrective(run, options);
  if (task == "sequence") return bdlstm::evaluate_sequence(run, options);
  return eval::evaluate(run, options);
}

std::string table_text(const std::vector<report::RunResult>& runs, const report::TableOptions& options) {
  if (!runs.empty() && runs.front().task == "sequence") return bdlstm::sequence_table(runs, options);
  return report::make_table(runs, options);
}

}  // namespace skinlab::cli

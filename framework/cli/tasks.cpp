#include "framework/cli/tasks.hpp"

namespace skinlab::cli {

bool untrained_method(const config::Config& config, const train::RunOptions& options) {
  if (options.task == "corrective") {
    return !densegats::CorrectiveConfig::from(config).corrective.baseline.empty();
  }
  if (options.binder.exists()) options.require_binder_sections(config);
  return options.binder.exists();
}

TaskTrainer::TaskTrainer(const config::Config& config) {
  if (train::RunOptions::from(config).task == "corrective") {
    corrective_ = std::make_unique<densegats::CorrectiveTrainer>(config);
  } else {
    skinning_ = std::make_unique<train::Trainer>(config);
  }
}

train::TrainResult TaskTrainer::fit(const RunDir& run, const train::FitLimits& limits) {
  return corrective_ ? corrective_->fit(run, limits) : skinning_->fit(run, limits);
}

bool TaskTrainer::validated() const {
  return corrective_ ? corrective_->has_validation() : !skinning_->data().part("val").empty();
}

eval::EvalReport evaluate_run(const RunDir& run, const eval::EvalOptions& options) {
  const config::Config config = config::Config::load(run.file("config.yaml"), options.overrides);
  return train::RunOptions::from(config).task == "corrective"
             ? densegats::evaluate_corrective(run, options)
             : eval::evaluate(run, options);
}

}  // namespace skinlab::cli

/// \file
/// DenseGATs' task, `task: corrective` (corrective deformation over LBS): its `corrective:`
/// section, trainer, evaluation and error-colour figures, registered in the task registry
/// (framework/task/task.hpp).

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <memory>

#include "experiments/densegats/corrective_figure.hpp"
#include "experiments/densegats/corrective_task.hpp"
#include "framework/core/error.hpp"
#include "framework/task/task.hpp"

namespace skinlab::densegats {

namespace {

class CorrectiveTaskTrainer final : public task::TaskTrainer {
 public:
  explicit CorrectiveTaskTrainer(const config::Config& config) : trainer_(config) {}
  train::TrainResult fit(const RunDir& run, const train::FitLimits& limits) override {
    return trainer_.fit(run, limits);
  }
  bool validated() const override { return trainer_.has_validation(); }

 private:
  CorrectiveTrainer trainer_;
};

class CorrectiveTask final : public task::Task {
 public:
  std::string name() const override { return "corrective"; }
  std::string section() const override { return "corrective"; }
  void check_model(const config::Node& model) const override {
    corrective_model_registry().create(model);
  }
  void validate(const config::Config& config) const override { CorrectiveConfig::from(config); }
  bool untrained(const config::Config& config, const train::RunOptions&) const override {
    return !CorrectiveConfig::from(config).corrective.baseline.empty();
  }
  void require_untrained_sections(const config::Config& config,
                                  const train::RunOptions&) const override {
    throw ConfigError(config.source() + ": a corrective config needs a 'model' (trained first) "
                      "or a 'corrective.baseline' to evaluate");
  }
  std::unique_ptr<task::TaskTrainer> trainer(const config::Config& config,
                                             train::World*) const override {
    return std::make_unique<CorrectiveTaskTrainer>(config);
  }
  eval::EvalReport evaluate(const RunDir& run, const eval::EvalOptions& options) const override {
    return evaluate_corrective(run, options);
  }
  void figures(const task::FigureOptions& options) const override {
    std::string command = fmt::format("skinlab figure {} --part {} --poses {} --out {}",
                                      fmt::join(options.runs, " "), options.part, options.poses,
                                      options.out.string());
    if (!options.characters.empty()) {
      command += fmt::format(" --characters {}", fmt::join(options.characters, ","));
    } else {
      command += fmt::format(" --count {}", options.count);
    }
    if (options.error_max_cm > 0) command += fmt::format(" --error-max {}", options.error_max_cm);
    write_corrective_figures(options, command);
  }
};

}  // namespace

SKINLAB_REGISTER_TASK(corrective, CorrectiveTask);

}  // namespace skinlab::densegats

/// \file
/// The framework's own task, `task: skinning` (the default): per-vertex bone weights of a
/// character (HeterSkinNet Sec. 3), trained by train::Trainer (data-parallel over processes),
/// evaluated by eval::evaluate (Table 3/4's metrics), compared by report::make_table, drawn as
/// per-vertex error maps (report/error_maps.hpp). Its methods are skinning `model`s and `binder`s.

#include <memory>

#include "framework/report/error_maps.hpp"
#include "framework/task/task.hpp"

namespace skinlab::task {

namespace {

class SkinningTrainer final : public TaskTrainer {
 public:
  SkinningTrainer(const config::Config& config, train::World* world) : trainer_(config, world) {}
  train::TrainResult fit(const RunDir& run, const train::FitLimits& limits) override {
    return trainer_.fit(run, limits);
  }
  bool validated() const override { return !trainer_.data().part("val").empty(); }

 private:
  train::Trainer trainer_;
};

class SkinningTask final : public Task {
 public:
  std::string name() const override { return "skinning"; }
  bool data_parallel() const override { return true; }
  std::unique_ptr<TaskTrainer> trainer(const config::Config& config,
                                       train::World* world) const override {
    return std::make_unique<SkinningTrainer>(config, world);
  }
  eval::EvalReport evaluate(const RunDir& run, const eval::EvalOptions& options) const override {
    return eval::evaluate(run, options);
  }
  void figures(const FigureOptions& options) const override { report::write_error_maps(options); }
};

}  // namespace

SKINLAB_REGISTER_TASK(skinning, SkinningTask);

}  // namespace skinlab::task

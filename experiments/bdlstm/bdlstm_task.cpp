/// \file
/// The mesh-sequence BiLSTM's task, `task: sequence`: its `sequences:` section, trainer,
/// evaluation on the held-out windows, Tables 1-2 and the `skinlab generate` command, registered
/// in the task registry (framework/task/task.hpp).

#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "experiments/bdlstm/sequence_table.hpp"
#include "experiments/bdlstm/sequence_task.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/task/task.hpp"
#include "framework/tensors/threads.hpp"

namespace skinlab::bdlstm {

namespace {

class SequenceTaskTrainer final : public task::TaskTrainer {
 public:
  explicit SequenceTaskTrainer(const config::Config& config) : trainer_(config) {}
  train::TrainResult fit(const RunDir& run, const train::FitLimits& limits) override {
    return trainer_.fit(run, limits);
  }
  /// Whether best.pt is chosen on the validation windows (sequences.val_fraction > 0; the paper
  /// has no validation set), else on the training loss.
  bool validated() const override { return trainer_.has_validation(); }

 private:
  SequenceTrainer trainer_;
};

/// `skinlab generate`: continues a clip with a trained network (generate_sequence).
int run_generate(const RunDir& run, const std::vector<std::string>& overrides,
                 const std::map<std::string, std::string>& values) {
  GenerateOptions options;
  options.overrides = overrides;
  options.initial_frames = task::int_option(values, "init-frames");
  options.frames = task::int_option(values, "frames");
  options.clip = task::string_option(values, "clip");
  if (values.count("start")) options.start = task::int_option(values, "start");
  options.checkpoint = task::string_option(values, "checkpoint", options.checkpoint);
  if (values.count("fps")) options.fps = task::double_option(values, "fps");
  const std::string out = task::string_option(values, "out");
  const config::Config config = config::Config::load(run.file("config.yaml"), overrides);
  const train::RunOptions o = train::RunOptions::from(config);
  set_torch_threads(values.count("threads") ? task::int_option(values, "threads") : o.threads);
  const GeneratedSequence g = generate_sequence(run, options, out);
  std::cout << fmt::format("{} / {}: {} frames generated from {} initial frames at frame {} "
                           "(held-out window {}..{}), checkpoint {} (epoch {})\n",
                           g.character, g.clip, options.frames, options.initial_frames, g.start,
                           g.test_begin, g.test_end - 1, options.checkpoint, g.epoch);
  for (std::size_t h = 0; h < g.error_mm.size(); ++h) {
    std::cout << fmt::format("  generated frame {:>2}: {:.2f} mm\n", h + 1, g.error_mm[h]);
  }
  if (g.error_mm.size() < static_cast<std::size_t>(options.frames)) {
    std::cout << fmt::format("  frames {}..{} run past the end of the clip (no ground truth)\n",
                             g.error_mm.size() + 1, options.frames);
  }
  std::cout << "wrote " << out << "/ (frame_*.obj, truth_*.obj, sequence.glb, truth.glb, "
            << "generate.json)\n";
  return 0;
}

class SequenceTask final : public task::Task {
 public:
  std::string name() const override { return "sequence"; }
  std::string section() const override { return "sequences"; }
  /// A sequence model is validated with the rest of the task's config (SequenceConfig::from).
  void check_model(const config::Node&) const override {}
  /// Its objective is sequences.objective (Eq. 3), not `losses:`; its data is a `data:` file
  /// or a `sequences.folder` (SequenceTrainer checks which).
  void require_training_sections(const config::Config& config,
                                 const train::RunOptions& options) const override {
    train::require_sections(config, "training", {{&options.model, "model: {type: bdlstm}"}});
  }
  void validate(const config::Config& config) const override { SequenceConfig::from(config); }
  bool untrained(const config::Config& config, const train::RunOptions&) const override {
    return !SequenceConfig::from(config).sequences.baseline.empty();
  }
  void require_untrained_sections(const config::Config& config,
                                  const train::RunOptions&) const override {
    throw ConfigError(config.source() + ": a sequence config needs a 'model' (trained first) "
                      "or a 'sequences.baseline' to evaluate");
  }
  std::unique_ptr<task::TaskTrainer> trainer(const config::Config& config,
                                             train::World*) const override {
    return std::make_unique<SequenceTaskTrainer>(config);
  }
  eval::EvalReport evaluate(const RunDir& run, const eval::EvalOptions& options) const override {
    return evaluate_sequence(run, options);
  }
  /// Qiao et al.'s Tables 1-2.
  std::string table(const std::vector<report::RunResult>& runs,
                    const report::TableOptions& options) const override {
    return sequence_table(runs, options);
  }
  std::vector<task::TaskCommand> commands() const override {
    const GenerateOptions d;
    return {{"generate",
             "continue a clip with a trained mesh-sequence network: OBJ frames and glTF",
             {{"out", "new directory for the frames", "", true},
              {"init-frames", "initial frames given (Table 1: 1 or 3)", std::to_string(d.initial_frames)},
              {"frames", "frames to generate", std::to_string(d.frames)},
              {"clip", "clip of the character (default: its first)", ""},
              {"start", "first initial frame (default: the start of the clip's held-out window)", ""},
              {"checkpoint", "best or last", d.checkpoint},
              {"fps", "playback rate of the glTF animations (default: the clip's, else 30)", ""},
              {"threads", "libtorch threads (default: the run config's `threads`; 0 = every core)", ""}},
             &run_generate}};
  }
};

}  // namespace

SKINLAB_REGISTER_TASK(sequence, SequenceTask);

}  // namespace skinlab::bdlstm

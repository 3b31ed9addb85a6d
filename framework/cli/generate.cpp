/// \file
/// `skinlab generate <run_dir> [key=value ...] --init-frames 1|3 --frames N --out DIR
/// [--clip NAME] [--start F] [--checkpoint best|last] [--fps R]`: a trained mesh-sequence
/// network (task: sequence) continues a clip of its character from its first frames; writes OBJ
/// frames, glTF morph-target animations and generate.json into a new directory
/// (experiments/bdlstm/sequence_task.hpp, generate_sequence).

#include <fmt/format.h>

#include <iostream>

#include "experiments/bdlstm/sequence_task.hpp"
#include "framework/cli/commands.hpp"
#include "framework/core/config.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/train/run_options.hpp"

namespace skinlab::cli {

namespace {

struct GenerateArgs {
  std::string run;
  std::string out;
  bdlstm::GenerateOptions options;
  int threads = -1;
};

int run_generate(const GenerateArgs& args) {
  const RunDir run = RunDir::open(args.run);
  const config::Config config = config::Config::load(run.file("config.yaml"), args.options.overrides);
  const train::RunOptions o = train::RunOptions::from(config);
  if (o.task != "sequence") {
    throw Error(args.run + ": a run of task '" + o.task +
                "'; generate continues mesh sequences (task: sequence)");
  }
  set_torch_threads(args.threads >= 0 ? args.threads : o.threads);
  const bdlstm::GeneratedSequence g = bdlstm::generate_sequence(run, args.options, args.out);
  std::cout << fmt::format("{} / {}: {} frames generated from {} initial frames at frame {} "
                           "(held-out window {}..{}), checkpoint {} (epoch {})\n",
                           g.character, g.clip, args.options.frames, args.options.initial_frames,
                           g.start, g.test_begin, g.test_end - 1, args.options.checkpoint, g.epoch);
  for (std::size_t h = 0; h < g.error_mm.size(); ++h) {
    std::cout << fmt::format("  generated frame {:>2}: {:.2f} mm\n", h + 1, g.error_mm[h]);
  }
  if (g.error_mm.size() < static_cast<std::size_t>(args.options.frames)) {
    std::cout << fmt::format("  frames {}..{} run past the end of the clip (no ground truth)\n",
                             g.error_mm.size() + 1, args.options.frames);
  }
  std::cout << "wrote " << args.out << "/ (frame_*.obj, truth_*.obj, sequence.glb, truth.glb, "
            << "generate.json)\n";
  return 0;
}

}  // namespace

Command add_generate(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "generate", "continue a clip with a trained mesh-sequence network: OBJ frames and glTF");
  auto args = std::make_shared<GenerateArgs>();
  cmd->add_option("run", args->run, "run directory of a task: sequence training")->required();
  cmd->add_option("overrides", args->options.overrides,
                  "key.sub=value assignments applied to the run's config (e.g. data.file=...)");
  cmd->add_option("--out", args->out, "new directory for the frames")->required();
  cmd->add_option("--init-frames", args->options.initial_frames, "initial frames given (Table 1: 1 or 3)")
      ->capture_default_str();
  cmd->add_option("--frames", args->options.frames, "frames to generate")->capture_default_str();
  cmd->add_option("--clip", args->options.clip, "clip of the character (default: its first)");
  cmd->add_option("--start", args->options.start,
                  "first initial frame (default: the start of the clip's held-out window)");
  cmd->add_option("--checkpoint", args->options.checkpoint, "best or last")->capture_default_str();
  cmd->add_option("--fps", args->options.fps,
                  "playback rate of the glTF animations (default: the clip's, else 30)");
  cmd->add_option("--threads", args->threads,
                  "libtorch threads (default: the run config's `threads`; 0 = every core)");
  return {cmd, [args] { return run_generate(*args); }};
}

}  // namespace skinlab::cli

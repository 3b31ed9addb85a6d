/// \file
/// `skinlab figure <run_dir>... [--part test] [--characters a,b | --count N] [--l1-max 1]
/// [--out dir]`: per-vertex error maps of evaluated runs side by side (HeterSkinNet Fig. 7 and
/// 10: L1 error of the weights; and the deformation error of Sec. 4.3 per vertex), one PNG per
/// character and map, and one vertex-coloured PLY per run, character and map
/// (framework/report/error_maps.hpp). The first run's task draws them (framework/task/task.hpp):
/// other tasks draw their own figures, e.g. the corrective task's error-colour meshes.

#include "framework/cli/commands.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/task/task.hpp"

namespace skinlab::cli {

Command add_figure(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "figure", "per-vertex L1 and deformation error maps of evaluated runs (PNG and PLY)");
  struct Args {
    task::FigureOptions options;
    std::string out;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("runs", args->options.runs, "evaluated run directories, one column each")->required();
  cmd->add_option("--part", args->options.part, "evaluated part (predictions/<part>.h5)")
      ->capture_default_str();
  cmd->add_option("--characters", args->options.characters, "characters to draw (default: --count)")
      ->delimiter(',');
  cmd->add_option("--count", args->options.count, "the first N characters of the part")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--l1-max", args->options.l1_max, "top of the L1 colour scale (L1 is in [0, 2])")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--poses", args->options.poses,
                  "corrective runs: evaluation poses per character, evenly spaced")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--error-max", args->options.error_max_cm,
                  "corrective runs: top of the error colour scale in cm (default: each "
                  "figure's 99th percentile)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--out", args->out, "output directory")->required();
  return {cmd, [args] {
            args->options.out = args->out;
            task::of_run(RunDir::open(args->options.runs.front())).figures(args->options);
            return 0;
          }};
}

}  // namespace skinlab::cli

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
    std::vector<std::string> runs;
    std::string part = "test";
    std::vector<std::string> characters;
    int count = 3;
    double l1_max = 1.0;
    int poses = 3;
    double error_max_cm = 0;
    std::string out;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("runs", args->runs, "evaluated run directories, one column each")->required();
  cmd->add_option("--part", args->part, "evaluated part (predictions/<part>.h5)")
      ->capture_default_str();
  cmd->add_option("--characters", args->characters, "characters to draw (default: --count)")
      ->delimiter(',');
  cmd->add_option("--count", args->count, "the first N characters of the part")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--l1-max", args->l1_max, "top of the L1 colour scale (L1 is in [0, 2])")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--poses", args->poses,
                  "corrective runs: evaluation poses per character, evenly spaced")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--error-max", args->error_max_cm,
                  "corrective runs: top of the error colour scale in cm (default: each "
                  "figure's 99th percentile)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--out", args->out, "output directory")->required();
  return {cmd, [args] {
            task::FigureOptions o;
            o.runs = args->runs;
            o.part = args->part;
            o.characters = args->characters;
            o.count = args->count;
            o.l1_max = args->l1_max;
            o.poses = args->poses;
            o.error_max_cm = args->error_max_cm;
            o.out = args->out;
            task::of_run(RunDir::open(args->runs.front())).figures(o);
            return 0;
          }};
}

}  // namespace skinlab::cli

/// \file
/// `skinlab eval <run_dir> [key=value ...] [--split test] [--checkpoint best|last]`: evaluates
/// a trained run on one part of its dataset split and writes eval_<part>.json/.csv and
/// predictions/ into the run directory (framework/eval/evaluator.hpp).

#include <fmt/format.h>

#include <iostream>

#include "framework/cli/commands.hpp"
#include "framework/core/config.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/eval/evaluator.hpp"
#include "framework/train/run_options.hpp"

namespace skinlab::cli {

namespace {

struct EvalArgs {
  std::string run;
  eval::EvalOptions options;
  bool no_predictions = false;
  int threads = -1;
};

int run_eval(EvalArgs args) {
  const RunDir run = RunDir::open(args.run);
  if (args.threads >= 0) {
    set_torch_threads(args.threads);
  } else {
    const config::Config config = config::Config::load(run.file("config.yaml"), args.options.overrides);
    set_torch_threads(train::RunOptions::from(config).threads);
  }
  args.options.predictions = !args.no_predictions;
  const eval::EvalReport r = eval::evaluate(run, args.options);
  std::cout << fmt::format("{} part of split '{}', {} characters, checkpoint {} (epoch {}), {:.1f} s\n",
                           r.part, r.split, r.characters.size(), r.checkpoint, r.epoch, r.seconds);
  for (const auto& [name, value] : r.mean) std::cout << fmt::format("  {}: {:.6g}\n", name, value);
  std::cout << "wrote " << r.json.string() << ", " << r.csv.string();
  if (!r.predictions.empty()) std::cout << ", " << r.predictions.string() << "/";
  std::cout << "\n";
  return 0;
}

}  // namespace

Command add_eval(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "eval", "evaluate a trained run on a split part: metrics, per-character CSV, predictions");
  auto args = std::make_shared<EvalArgs>();
  cmd->add_option("run", args->run, "run directory (results/<experiment>/<run_id>)")->required();
  cmd->add_option("overrides", args->options.overrides,
                  "key.sub=value assignments applied to the run's config (e.g. data.file=...)");
  cmd->add_option("--split", args->options.part, "part of the configured split: train, val or test")
      ->capture_default_str();
  cmd->add_option("--checkpoint", args->options.checkpoint, "best or last")->capture_default_str();
  cmd->add_flag("--no-predictions", args->no_predictions,
                "do not write predictions/ (rig text and HDF5)");
  cmd->add_option("--threads", args->threads,
                  "libtorch threads (default: the run config's `threads`; 0 = every core)");
  return {cmd, [args] { return run_eval(*args); }};
}

}  // namespace skinlab::cli

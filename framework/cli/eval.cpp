/// \file
/// `skinlab eval <run_dir> [key=value ...] [--split test] [--checkpoint best|last]`: evaluates
/// a trained run on one part of its dataset split and writes eval_<part>.json/.csv and
/// predictions/ into the run directory (framework/eval/evaluator.hpp).
///
/// `skinlab eval <config.yaml> [key=value ...] [--split test] [--run-id ID]`: a config with a
/// `binder:` (weights from geometry alone) needs no training; this creates its run directory
/// (resolved config, env.json) and evaluates it there.
///
/// `skinlab eval <run_dir> key=value ... --run-id ID`: the run's checkpoint under the overrides,
/// as a run of its own, `<results_dir>/<experiment>/<ID>` (experiment after the overrides, e.g.
/// `experiment=..._leaf_bias model.leaf_bias=0.5`): the config with the overrides applied,
/// env.json, a copy of the source's metrics.jsonl and its checkpoint (`--checkpoint`, a hard link
/// where the file system allows, else a copy), so `skinlab table` compares it with its source
/// like any two runs. For settings that act after training only
/// (models::BranchedModelOptions::leaf_bias, models::PriorOptions::keep_prior_outside and
/// prior_mix, the metrics' pruning, another dataset file); an override under which the
/// checkpoint does not load is an error before the directory is made.
///
/// `--nproc N` shards the characters of a skinning run over N worker processes on this machine
/// (core/launch.hpp); rank 0 gathers the values and predictions and writes the files. A process
/// started with WORLD_SIZE > 1 is one rank of such an evaluation (train/distributed.hpp).
///
/// The process that writes the files (alone, the `--nproc` launcher, or rank 0) holds
/// `<run>/eval_<part>.lock` (core/output_lock.hpp): a second evaluation of the same part of the
/// same run fails at once, naming the first. Evaluating a run while it trains is allowed.

#include <fmt/format.h>

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>

#include "framework/tensors/threads.hpp"
#include "framework/cli/commands.hpp"
#include "framework/task/task.hpp"
#include "framework/core/config.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/eval/evaluator.hpp"
#include "framework/core/error.hpp"
#include "framework/core/launch.hpp"
#include "framework/core/output_lock.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/distributed.hpp"
#include "framework/train/run_options.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::cli {

namespace {

struct EvalArgs {
  std::string run;
  std::string run_id;
  eval::EvalOptions options;
  bool no_predictions = false;
  int threads = -1;
  int nproc = 0;
};

/// The run directory of a binder config (see the file comment); the overrides are applied to the
/// saved config, so they are cleared from `args`.
RunDir create_binder_run(EvalArgs& args) {
  const config::Config config = config::Config::load(args.run, args.options.overrides);
  const train::RunOptions o = train::RunOptions::from(config);
  if (o.model.exists()) {
    throw Error(args.run + ": has a 'model', which must be trained first: `skinlab train " +
                args.run + "`, then `skinlab eval <its run directory>`");
  }
  const task::Task& task = task::get(o.task);
  if (!task.untrained(config, o)) task.require_untrained_sections(config, o);
  args.options.overrides.clear();
  RunDir run = train::create_run(config, o, args.run_id, command_line());
  std::cout << "run: " << run.path().string() << "\n";
  return run;
}

/// The run of a trained run's checkpoint under overrides (see the file comment); the overrides
/// are applied to the saved config, so they are cleared from `args`.
RunDir derive_run(EvalArgs& args) {
  namespace fs = std::filesystem;
  const RunDir source = RunDir::open(args.run);
  if (args.options.overrides.empty()) {
    throw Error("eval: --run-id with a trained run (" + args.run +
                ") makes a run of its checkpoint under overrides, and none were given");
  }
  const fs::path checkpoint = train::existing_checkpoint(source.path(), args.options.checkpoint);
  const config::Config config =
      config::Config::load(source.file("config.yaml"), args.options.overrides);
  const train::RunOptions o = train::RunOptions::from(config);
  // The checkpoint must load into the model the overrides describe: an error before any
  // directory is made (e.g. an override that changes a width).
  train::load_checkpoint(checkpoint, *train::build_model(o));
  RunDir run = train::create_run(config, o, args.run_id, command_line());
  std::cout << "run: " << run.path().string() << " (the checkpoint of " << args.run << ")\n";
  const fs::path linked = run.file(checkpoint.filename().string());
  std::error_code no_link;
  fs::create_hard_link(checkpoint, linked, no_link);
  if (no_link) fs::copy_file(checkpoint, linked);
  if (fs::exists(source.file("metrics.jsonl"))) {
    fs::copy_file(source.file("metrics.jsonl"), run.file("metrics.jsonl"));
  }
  args.options.overrides.clear();
  return run;
}

int run_eval(EvalArgs args) {
  const bool from_config = std::filesystem::is_regular_file(args.run);
  const RunDir run = from_config        ? create_binder_run(args)
               : !args.run_id.empty() ? derive_run(args)
                                      : RunDir::open(args.run);
  std::optional<OutputLock> lock;  // the launcher's workers write under their launcher's lock
  if (std::getenv("SKINLAB_LAUNCHED") == nullptr && train::WorldOptions::from_environment().rank == 0) {
    lock.emplace(eval_lock_of(run.path(), args.options.part),
                 run.file("eval_" + args.options.part + ".json").string(), command_line());
  }
  if (args.nproc > 1) {
    const config::Config config = config::Config::load(run.file("config.yaml"), args.options.overrides);
    task::require_data_parallel(task::of(config), run.path().string(), "sharded evaluation (--nproc)",
                                "is evaluated in one process");
    LaunchOptions launch;
    launch.nproc = args.nproc;
    launch.args = {"eval", run.path().string(), "--split", args.options.part, "--checkpoint",
                   args.options.checkpoint, "--threads", std::to_string(std::max(args.threads, 1))};
    launch.args.insert(launch.args.end(), args.options.overrides.begin(), args.options.overrides.end());
    if (args.no_predictions) launch.args.push_back("--no-predictions");
    launch.environment = {"SKINLAB_LAUNCHED=1"};
    launch_local(launch);
    return 0;
  }
  train::World world(train::WorldOptions::from_environment());
  if (world.distributed()) {
    args.options.world = &world;
    if (!world.writer()) spdlog::set_level(spdlog::level::warn);
  }
  if (args.threads >= 0) {
    set_torch_threads(args.threads);
  } else {
    const config::Config config = config::Config::load(run.file("config.yaml"), args.options.overrides);
    set_torch_threads(train::RunOptions::from(config).threads);
  }
  args.options.predictions = !args.no_predictions;
  const eval::EvalReport r = task::evaluate_run(run, args.options);
  if (!world.writer()) return 0;
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
  cmd->add_option("run", args->run,
                  "run directory (results/<experiment>/<run_id>), or the config of a binder")
      ->required();
  cmd->add_option("--run-id", args->run_id,
                  "name of the new run directory of a binder config (default: the UTC time), or "
                  "of a trained run's checkpoint evaluated under the overrides");
  cmd->add_option("overrides", args->options.overrides,
                  "key.sub=value assignments applied to the run's config (e.g. data.file=...)");
  cmd->add_option("--split", args->options.part, "part of the configured split: train, val or test")
      ->capture_default_str();
  cmd->add_option("--checkpoint", args->options.checkpoint, "best or last")->capture_default_str();
  cmd->add_flag("--no-predictions", args->no_predictions,
                "do not write predictions/ (rig text and HDF5)");
  cmd->add_option("--nproc", args->nproc,
                  "shard the characters over this many processes on this machine (skinning runs)");
  cmd->add_option("--threads", args->threads,
                  "libtorch threads (default: the run config's `threads`; 0 = every core)");
  return {cmd, [args] { return run_eval(*args); }};
}

}  // namespace skinlab::cli

/// \file
/// `skinlab train <config> [key=value ...] [--resume <run_dir>] [--threads N] [--run-id ID]`:
/// trains the config's model on the train part of its dataset split (framework/train/), in a new
/// run directory `<results_dir>/<experiment>/<run_id>/`, or continues the run in `--resume`.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <iostream>
#include <optional>

#include "framework/cli/commands.hpp"
#include "framework/cli/tasks.hpp"
#include "framework/core/config.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/logging.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::cli {

namespace {

struct TrainArgs {
  std::string file;
  std::vector<std::string> overrides;
  std::string resume;
  std::string run_id;
  int threads = -1;
};

int run_train(TrainArgs args) {
  // `train --resume <dir> key=value`: the first assignment lands in the config's position.
  if (!args.resume.empty() && args.file.find('=') != std::string::npos &&
      !std::filesystem::exists(args.file)) {
    args.overrides.insert(args.overrides.begin(), args.file);
    args.file.clear();
  }
  if (args.file.empty() && args.resume.empty()) {
    throw Error("train: give an experiment config, or --resume <run_dir>");
  }
  std::optional<RunDir> run;
  std::optional<config::Config> config;
  if (!args.resume.empty()) {
    if (!args.run_id.empty()) throw Error("train: --run-id and --resume exclude each other");
    run = RunDir::open(args.resume);
    config = config::Config::load(run->file("config.yaml"));
    if (!args.file.empty()) {
      // The run's own config governs; a config given as well must resolve to the same thing.
      const config::Config given = config::Config::load(args.file, args.overrides);
      if (given.to_yaml() != config->to_yaml()) {
        throw Error("train --resume: " + args.file +
                    " (with the overrides) differs from the run's " +
                    run->file("config.yaml").string() +
                    "; a run resumes with its own config (give only --resume)");
      }
    } else if (!args.overrides.empty()) {
      throw Error("train --resume: overrides would change the run's config; give only --resume");
    }
  } else {
    config = config::Config::load(args.file, args.overrides);
  }
  const train::RunOptions options = train::RunOptions::from(*config);
  const int threads = set_torch_threads(args.threads >= 0 ? args.threads : options.threads);

  // Everything that can fail on the config, the dataset or the model fails here, before a run
  // directory exists. The config's task decides the trainer.
  TaskTrainer trainer(*config);
  if (!run) {
    run = train::create_run(*config, options, args.run_id, command_line());
  } else {
    int n = 1;
    while (std::filesystem::exists(run->file(fmt::format("env_resume_{}.json", n)))) ++n;
    write_file_atomic(run->file(fmt::format("env_resume_{}.json", n)),
                      collect_environment(static_cast<std::uint64_t>(options.seed), command_line())
                              .dump(2) + "\n");
  }
  logging::add_file(run->log_file());
  std::cout << "run: " << run->path().string() << std::endl;
  spdlog::info("training {} ({} threads) in {}", options.experiment, threads, run->path().string());

  const train::TrainResult r = trainer.fit(*run);
  std::cout << fmt::format(
      "{} {} epochs{} ({} this session, {:.1f} s); best epoch {} with {} loss {:.6g}\n",
      r.early_stopped ? "stopped early after" : "trained", r.epochs,
      r.resumed ? " in total" : "", r.epochs_this_call, r.seconds, r.best_epoch,
      trainer.validated() ? "validation" : "train", r.best_loss);
  std::cout << "checkpoints: " << run->file(train::kBestCheckpoint).string() << ", "
            << run->file(train::kLastCheckpoint).string() << "\n";
  return 0;
}

}  // namespace

Command add_train(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "train", "train a model (HeterSkinNet Sec. 4.2) into a new run directory, or resume one");
  auto args = std::make_shared<TrainArgs>();
  cmd->add_option("file", args->file, "experiment config (YAML)");
  cmd->add_option("overrides", args->overrides, "key.sub=value assignments, applied in order");
  cmd->add_option("--resume", args->resume,
                  "continue the run in this directory from its last.pt (same config, seed)");
  cmd->add_option("--run-id", args->run_id,
                  "name of the new run directory (default: the UTC time)");
  cmd->add_option("--threads", args->threads,
                  "libtorch threads (default: the config's `threads`; 0 = every core); a "
                  "bit-identical resume needs the same count");
  return {cmd, [args] { return run_train(*args); }};
}

}  // namespace skinlab::cli

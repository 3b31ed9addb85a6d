/// \file
/// `skinlab train <config> [key=value ...] [--resume <run_dir>] [--threads N] [--run-id ID]
/// [--nproc N]`: trains the config's model on the train part of its dataset split
/// (framework/train/), in a new run directory `<results_dir>/<experiment>/<run_id>/`, or
/// continues the run in `--resume`.
///
/// Data parallel (framework/train/distributed.hpp): `--nproc N` creates the run directory and
/// starts N worker processes on this machine (core/launch.hpp), each `train --resume <run>`
/// with the launcher's environment; a process started with WORLD_SIZE > 1 in its environment
/// (by `--nproc`, or by a cluster's job script on several nodes, with MASTER_ADDR/MASTER_PORT)
/// is one rank of the run. Started by hand, every rank needs the same `--run-id` (or
/// `--resume`): rank 0 creates the directory, the others wait for it. Only rank 0 logs to the
/// console at info level and writes the run's files.
///
/// One trainer per run: the process that writes the run (alone, the `--nproc` launcher, or rank
/// 0) holds `<run>/train.lock` (core/output_lock.hpp) from when the run is created or opened to
/// the end, so a second `skinlab train --resume` of it fails at once, naming the first.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <iostream>
#include <optional>

#include "framework/tensors/threads.hpp"
#include "framework/cli/commands.hpp"
#include "framework/task/task.hpp"
#include "framework/core/config.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/launch.hpp"
#include "framework/core/logging.hpp"
#include "framework/core/output_lock.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/train/distributed.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::cli {

namespace {

struct TrainArgs {
  std::string file;
  std::vector<std::string> overrides;
  std::string resume;
  std::string run_id;
  int threads = -1;
  int nproc = 0;
};

/// `--nproc N`: validates the config, creates (or opens) the run, writes its env record with
/// the world size and runs N workers on it.
int launch_train(const TrainArgs& args, const std::optional<RunDir>& resumed,
                 const config::Config& config, std::optional<OutputLock>& lock) {
  const train::RunOptions options = train::RunOptions::from(config);
  options.require_training_sections(config);
  task::require_data_parallel(task::get(options.task), config.source(),
                              "data-parallel training (--nproc)", "trains in one process");
  const int threads = threads_per_worker(args.threads >= 0 ? args.threads : options.threads, args.nproc);
  nlohmann::json env = collect_environment(static_cast<std::uint64_t>(options.seed), command_line());
  env["world_size"] = args.nproc;
  env["threads_per_process"] = threads;
  std::optional<RunDir> run = resumed;
  if (!run) {
    run = RunDir::create(options.results_dir, options.experiment, args.run_id);
    lock.emplace(train_lock_of(run->path()), run->path().string(), command_line());
    run->write_config(config.to_yaml());
    run->write_env(env);
  } else {
    int n = 1;
    while (std::filesystem::exists(run->file(fmt::format("env_resume_{}.json", n)))) ++n;
    write_file_atomic(run->file(fmt::format("env_resume_{}.json", n)), env.dump(2) + "\n");
  }
  std::cout << "run: " << run->path().string() << std::endl;
  LaunchOptions launch;
  launch.nproc = args.nproc;
  launch.args = {"train", "--resume", run->path().string(), "--threads", std::to_string(threads)};
  launch.environment = {"SKINLAB_LAUNCHED=1"};
  try {
    launch_local(launch);
  } catch (const Error& e) {
    throw Error(std::string(e.what()) + "; continue from its last checkpoint with `skinlab train --resume " +
                run->path().string() + "` (any --nproc)");
  }
  std::cout << "checkpoints: " << run->file(train::kBestCheckpoint).string() << ", "
            << run->file(train::kLastCheckpoint).string() << "\n";
  return 0;
}

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
  const bool launched = std::getenv("SKINLAB_LAUNCHED") != nullptr;
  const train::WorldOptions world_options = train::WorldOptions::from_environment();
  // The launcher's workers train under its lock; of a world started by hand, rank 0 holds it.
  const bool locks = !launched && world_options.rank == 0;
  std::optional<OutputLock> lock;
  std::optional<RunDir> run;
  std::optional<config::Config> config;
  if (!args.resume.empty()) {
    if (!args.run_id.empty()) throw Error("train: --run-id and --resume exclude each other");
    run = RunDir::open(args.resume);
    if (locks) lock.emplace(train_lock_of(run->path()), run->path().string(), command_line());
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
  if (args.nproc > 1) return launch_train(args, run, *config, lock);
  const train::RunOptions options = train::RunOptions::from(*config);
  const int threads = set_torch_threads(args.threads >= 0 ? args.threads : options.threads);

  // One rank of a data-parallel run when WORLD_SIZE > 1 (see the file comment).
  if (world_options.distributed() && !run && args.run_id.empty()) {
    throw Error("train: a rank of a data-parallel run (WORLD_SIZE > 1) needs --run-id or "
                "--resume, the same for every rank");
  }
  train::World world(world_options);
  if (world.distributed() && !world.writer()) spdlog::set_level(spdlog::level::warn);

  // Everything that can fail on the config, the dataset or the model fails here, before a run
  // directory exists. The config's task decides the trainer.
  const std::unique_ptr<task::TaskTrainer> trainer = task::make_trainer(*config, &world);
  if (!run) {
    if (world.writer()) {
      run = train::create_run(*config, options, args.run_id, command_line());
      if (locks) lock.emplace(train_lock_of(run->path()), run->path().string(), command_line());
    }
    world.barrier();  // the other ranks open what rank 0 created
    if (!run) run = RunDir::open(std::filesystem::path(options.results_dir) / options.experiment / args.run_id);
  } else if (world.writer() && !launched) {
    int n = 1;
    while (std::filesystem::exists(run->file(fmt::format("env_resume_{}.json", n)))) ++n;
    nlohmann::json env = collect_environment(static_cast<std::uint64_t>(options.seed), command_line());
    if (world.distributed()) env["world_size"] = world.size();
    write_file_atomic(run->file(fmt::format("env_resume_{}.json", n)), env.dump(2) + "\n");
  }
  if (world.writer()) {
    logging::add_file(run->log_file());
    if (!launched) std::cout << "run: " << run->path().string() << std::endl;
  }
  spdlog::info("training {} ({} threads{}) in {}", options.experiment, threads,
               world.distributed() ? fmt::format(" in each of {} processes", world.size()) : "",
               run->path().string());

  const train::TrainResult r = trainer->fit(*run, {});
  if (!world.writer()) return 0;
  std::cout << fmt::format(
      "{} {} epochs{} ({} this session, {:.1f} s); best epoch {} with {} loss {:.6g}\n",
      r.early_stopped ? "stopped early after" : "trained", r.epochs,
      r.resumed ? " in total" : "", r.epochs_this_call, r.seconds, r.best_epoch,
      trainer->validated() ? "validation" : "train", r.best_loss);
  if (!launched) {
    std::cout << "checkpoints: " << run->file(train::kBestCheckpoint).string() << ", "
              << run->file(train::kLastCheckpoint).string() << "\n";
  }
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
  cmd->add_option("--nproc", args->nproc,
                  "train data-parallel in this many processes on this machine (c10d/Gloo); "
                  "train.batch characters per process and step");
  cmd->add_option("--threads", args->threads,
                  "libtorch threads (default: the config's `threads`; 0 = every core); a "
                  "bit-identical resume needs the same count");
  return {cmd, [args] { return run_train(*args); }};
}

}  // namespace skinlab::cli

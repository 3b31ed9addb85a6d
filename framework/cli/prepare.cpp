/// \file
/// `skinlab prepare <configs/datasets/<name>.yaml> [key=value ...] [--threads N]
/// [--keep-partial] [--nproc N]`: runs the dataset builders, preprocesses every character
/// (HeterSkinNet Sec. 4.1) in parallel and writes the one dataset file
/// (framework/data/prepare.hpp).
///
/// `--nproc N` shards the characters over N worker processes on this machine (core/launch.hpp),
/// each writing its characters' partial files, then merges them into the one file. A process
/// started with WORLD_SIZE > 1 (several nodes sharing the output's file system, with
/// MASTER_ADDR/MASTER_PORT) prepares shard RANK and waits for the others; rank 0 merges.
///
/// One writer per output: the process that writes the output file (alone, the `--nproc`
/// launcher, or rank 0) holds `<output>.lock` from the start (core/output_lock.hpp); a second
/// `skinlab prepare` of the same output fails at once, naming the first.

#include <fmt/format.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>

#include "framework/cli/commands.hpp"
#include "framework/core/config.hpp"
#include "framework/core/launch.hpp"
#include "framework/core/output_lock.hpp"
#include "framework/data/prepare.hpp"
#include "framework/train/distributed.hpp"

namespace skinlab::cli {

namespace {

struct PrepareArgs {
  std::string file;
  std::vector<std::string> overrides;
  data::PrepareOptions options;
  int nproc = 0;
};

int run_prepare(PrepareArgs args) {
  const config::Config config = config::Config::load(args.file, args.overrides);
  const data::PrepareConfig prepare = data::PrepareConfig::from(config);
  const bool launched = std::getenv("SKINLAB_LAUNCHED") != nullptr;
  const train::WorldOptions world_options = train::WorldOptions::from_environment();
  std::optional<OutputLock> lock;  // the launcher's workers write under their launcher's lock
  if (!launched && (args.nproc > 1 || world_options.rank == 0)) {
    if (prepare.output.has_parent_path()) std::filesystem::create_directories(prepare.output.parent_path());
    lock.emplace(lock_file_of(prepare.output), prepare.output.string(), command_line());
  }
  if (args.nproc > 1) {
    LaunchOptions launch;
    launch.nproc = args.nproc;
    launch.args = {"prepare", args.file};
    launch.args.insert(launch.args.end(), args.overrides.begin(), args.overrides.end());
    const int threads = threads_per_worker(args.options.threads, args.nproc);
    launch.args.insert(launch.args.end(), {"--threads", std::to_string(threads), "--keep-partial"});
    launch.environment = {"SKINLAB_LAUNCHED=1"};
    launch_local(launch);  // each worker prepares its shard
  } else if (const train::WorldOptions& w = world_options; w.distributed()) {
    args.options.shard_index = w.rank;
    args.options.shard_count = w.size;
    args.options.progress = args.options.progress && w.rank == 0;
    data::prepare_dataset(prepare, args.options);
    if (launched) return 0;  // the launcher merges; no process group needed
    train::World world(w);
    world.barrier();
    if (!world.writer()) return 0;
    args.options.shard_index = 0;
    args.options.shard_count = 1;
  }
  const data::PrepareReport r = data::prepare_dataset(prepare, args.options);
  std::cout << fmt::format(
      "prepared {}: {} characters ({}{} computed, {} reused), {} excluded, {:.2f} s\n",
      r.output.string(), r.characters,
      r.copies > 0 ? fmt::format("{} of them augmented copies; ", r.copies) : std::string(),
      r.computed, r.reused, r.excluded.size(), r.seconds);
  for (const auto& e : r.excluded) {
    std::cout << fmt::format("  excluded {}:{}: {}\n", e.source, e.path, e.reason);
  }
  return 0;
}

}  // namespace

Command add_prepare(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "prepare", "build and preprocess a dataset into one HDF5 file (configs/datasets/*.yaml)");
  auto args = std::make_shared<PrepareArgs>();
  cmd->add_option("file", args->file, "dataset config (YAML)")->required();
  cmd->add_option("overrides", args->overrides, "key.sub=value assignments, applied in order");
  cmd->add_option("--threads", args->options.threads,
                  "characters processed in parallel (and TBB threads); 0 = every core")
      ->capture_default_str();
  cmd->add_flag("--keep-partial", args->options.keep_partial,
                "keep <output>.partial/ (per-character files) after the merge");
  cmd->add_option("--nproc", args->nproc,
                  "shard the characters over this many processes on this machine, then merge");
  return {cmd, [args] { return run_prepare(*args); }};
}

}  // namespace skinlab::cli

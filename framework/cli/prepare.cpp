/// \file
/// `skinlab prepare <configs/datasets/<name>.yaml> [key=value ...] [--threads N]
/// [--keep-partial]`: runs the dataset builders, preprocesses every character (HeterSkinNet
/// Sec. 4.1) in parallel and writes the one dataset file (framework/data/prepare.hpp).

#include <fmt/format.h>

#include <iostream>

#include "framework/cli/commands.hpp"
#include "framework/core/config.hpp"
#include "framework/data/prepare.hpp"

namespace skinlab::cli {

namespace {

struct PrepareArgs {
  std::string file;
  std::vector<std::string> overrides;
  data::PrepareOptions options;
};

int run_prepare(const PrepareArgs& args) {
  const config::Config config = config::Config::load(args.file, args.overrides);
  const data::PrepareConfig prepare = data::PrepareConfig::from(config);
  const data::PrepareReport r = data::prepare_dataset(prepare, args.options);
  std::cout << fmt::format(
      "prepared {}: {} characters ({} computed, {} reused), {} excluded, {:.2f} s\n",
      r.output.string(), r.characters, r.computed, r.reused, r.excluded.size(), r.seconds);
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
  return {cmd, [args] { return run_prepare(*args); }};
}

}  // namespace skinlab::cli

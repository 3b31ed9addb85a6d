/// \file
/// `skinlab`: the one command-line entry point. Subcommands parse their arguments and call
/// library code; this is the only place where an exception becomes a message and an exit status.

#include <CLI/CLI.hpp>
#include <c10/util/Exception.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "framework/tensors/threads.hpp"
#include "framework/core/config.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/interrupt.hpp"
#include "framework/core/logging.hpp"
#include "framework/core/registry.hpp"
#include "framework/cli/commands.hpp"
#include "framework/task/task.hpp"

namespace skinlab::cli {

namespace {

int run_info(bool as_json) {
  nlohmann::json registries = nlohmann::json::object();
  for (const auto* registry : all_registries()) registries[registry->name()] = registry->keys();
  const GitState& git = build_git_state();
  if (as_json) {
    nlohmann::json out = {{"version", SKINLAB_VERSION}};
    out.update(git_json(git));
    out.update({{"libraries", library_versions()},
                {"threads", torch_threads()},
                {"registries", registries}});
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  std::cout << "skinlab " << SKINLAB_VERSION << " (git " << git.commit.substr(0, 12)
            << (git.dirty ? ", modified" : "") << ")\n";
  std::cout << "source: " << source_dir().string() << "\n";
  std::cout << "libraries:\n";
  const nlohmann::json versions = library_versions();
  for (const auto& [name, version] : versions.items()) {
    std::cout << "  " << name << ": " << version.get<std::string>() << "\n";
  }
  std::cout << "threads: " << torch_threads() << "\n";
  std::cout << "registries:\n";
  for (const auto* registry : all_registries()) {
    std::string keys;
    for (const auto& k : registry->keys()) keys += (keys.empty() ? "" : ", ") + k;
    std::cout << "  " << registry->name() << ": " << (keys.empty() ? "(none yet)" : keys) << "\n";
  }
  return 0;
}

std::vector<std::string>& command_line_storage() {
  static std::vector<std::string> args;
  return args;
}

}  // namespace

const std::vector<std::string>& command_line() { return command_line_storage(); }

Command add_info(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "versions, threads and every registry with its keys");
  auto as_json = std::make_shared<bool>(false);
  cmd->add_flag("--json", *as_json, "print as JSON");
  return {cmd, [as_json] { return run_info(*as_json); }};
}

Command add_config(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "config", "print the fully resolved config (bases merged, overrides applied, validated)");
  auto file = std::make_shared<std::string>();
  auto overrides = std::make_shared<std::vector<std::string>>();
  cmd->add_option("file", *file, "experiment config (YAML)")->required();
  cmd->add_option("overrides", *overrides, "key.sub=value assignments, applied in order");
  return {cmd, [file, overrides] {
            const config::Config config = config::Config::load(*file, *overrides);
            // Validates every section before printing (the tasks' own sections too).
            task::of(config).validate(config);
            std::cout << config.to_yaml();
            return 0;
          }};
}

}  // namespace skinlab::cli

int main(int argc, char** argv) {
  skinlab::install_interrupt_cleanup("skinlab");
  skinlab::keep_freed_memory();
  skinlab::cli::command_line_storage().assign(argv, argv + argc);
  CLI::App app{"skinlab: learned character skinning (HeterSkinNet and baselines)"};
  app.require_subcommand(1);
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
      ->capture_default_str();
  int threads = 0;
  app.add_option("--threads", threads, "libtorch threads; 0 = every hardware thread")
      ->capture_default_str();

  std::vector<skinlab::cli::Command> commands = {
      skinlab::cli::add_info(app), skinlab::cli::add_config(app),
      skinlab::cli::add_distance(app), skinlab::cli::add_prepare(app),
      skinlab::cli::add_dataset_info(app), skinlab::cli::add_dataset_card(app),
      skinlab::cli::add_train(app), skinlab::cli::add_eval(app),
      skinlab::cli::add_table(app), skinlab::cli::add_curves(app), skinlab::cli::add_figure(app),
      skinlab::cli::add_sweep(app), skinlab::cli::add_predict(app),
      skinlab::cli::add_bundle(app), skinlab::cli::add_export_parameters(app),
      skinlab::cli::add_export(app),
      skinlab::cli::add_score(app)};
  try {  // the tasks' own commands: building the tasks can fail on a bad registration
    skinlab::verify_registries();
    for (auto& command : skinlab::cli::add_task_commands(app)) commands.push_back(std::move(command));
  } catch (const std::exception& e) {
    std::cerr << "skinlab: error: " << e.what() << "\n";
    return 1;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  try {
    skinlab::logging::init(log_level);
    skinlab::verify_registries();
    skinlab::set_torch_threads(threads);
    for (const auto& command : commands) {
      if (command.app->parsed()) return command.run();
    }
  } catch (const c10::Error& e) {  // a check inside the tensor code: its message, no C++ backtrace
    std::fflush(stdout);
    std::cerr << "skinlab: error: " << e.what_without_backtrace() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::cerr << "skinlab: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

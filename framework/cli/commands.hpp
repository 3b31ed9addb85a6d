#pragma once
/// \file
/// Subcommands of `skinlab`. Each `add_*` declares its options on `app` and returns the
/// subcommand; `main` runs the one the user chose. Each `run` may throw; `main` reports.

#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace skinlab::cli {

/// A parsed subcommand and what running it does.
struct Command {
  CLI::App* app;
  std::function<int()> run;
};

Command add_info(CLI::App& app);
Command add_config(CLI::App& app);
Command add_distance(CLI::App& app);
Command add_prepare(CLI::App& app);
Command add_dataset_info(CLI::App& app);
Command add_dataset_card(CLI::App& app);
Command add_train(CLI::App& app);
Command add_eval(CLI::App& app);
Command add_table(CLI::App& app);
Command add_curves(CLI::App& app);
Command add_figure(CLI::App& app);
Command add_sweep(CLI::App& app);
Command add_predict(CLI::App& app);
Command add_bundle(CLI::App& app);
Command add_export_parameters(CLI::App& app);
Command add_export(CLI::App& app);
Command add_score(CLI::App& app);
/// Every task's own subcommands (framework/task/task.hpp, Task::commands).
std::vector<Command> add_task_commands(CLI::App& app);

/// The command line `skinlab` was started with (recorded in a run's env.json).
const std::vector<std::string>& command_line();

}  // namespace skinlab::cli

/// \file
/// The subcommands tasks add (framework/task/task.hpp, Task::commands), e.g. the sequence task's
/// `skinlab generate <run_dir> [key=value ...] --out DIR ...`: each takes a run directory of its
/// task, overrides of the run's config and the task's own `--name value` options.

#include <map>
#include <memory>

#include "framework/cli/commands.hpp"
#include "framework/core/error.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/task/task.hpp"

namespace skinlab::cli {

namespace {

struct TaskCommandArgs {
  std::string run;
  std::vector<std::string> overrides;
  std::map<std::string, std::string> values;
};

}  // namespace

std::vector<Command> add_task_commands(CLI::App& app) {
  std::vector<Command> out;
  for (const task::Task* t : task::all()) {
    for (const task::TaskCommand& command : t->commands()) {
      auto* cmd = app.add_subcommand(command.name, command.help);
      auto args = std::make_shared<TaskCommandArgs>();
      cmd->add_option("run", args->run, "run directory of a task: " + t->name() + " training")
          ->required();
      cmd->add_option("overrides", args->overrides,
                      "key.sub=value assignments applied to the run's config (e.g. data.file=...)");
      for (const task::CommandOption& option : command.options) {
        if (!option.default_value.empty()) args->values[option.name] = option.default_value;
        auto* o = cmd->add_option("--" + option.name, args->values[option.name], option.help);
        if (option.required) o->required();
        if (!option.default_value.empty()) o->default_str(option.default_value);
      }
      const std::string task_name = t->name();
      out.push_back({cmd, [args, command, task_name] {
                       const RunDir run = RunDir::open(args->run);
                       const task::Task& task = task::of_run(run);
                       if (task.name() != task_name) {
                         throw Error(args->run + ": a run of task '" + task.name() + "'; " +
                                     command.name + " is the " + task_name + " task's command");
                       }
                       std::map<std::string, std::string> values;
                       for (const auto& [name, value] : args->values) {
                         if (!value.empty()) values[name] = value;
                       }
                       return command.run(run, args->overrides, values);
                     }});
    }
  }
  return out;
}

}  // namespace skinlab::cli

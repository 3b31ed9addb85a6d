#include "framework/task/task.hpp"

#include <exception>
#include <mutex>

#include "framework/core/error.hpp"
#include "framework/models/model.hpp"

namespace skinlab::task {

void Task::check_model(const config::Node& model) const { model_registry().create(model); }

void Task::require_training_sections(const config::Config& config,
                                     const train::RunOptions& options) const {
  train::require_sections(config, "training",
                          {{&options.model, "model: {type: ...}"},
                           {&options.losses, "losses: [{type: kl, weight: 1.0}, ...]"},
                           {&options.data_node, train::kDataExample}});
}

void Task::validate(const config::Config& config) const { train::RunOptions::from(config); }

bool Task::untrained(const config::Config& config, const train::RunOptions& options) const {
  if (options.binder.exists()) options.require_binder_sections(config);
  return options.binder.exists();
}

void Task::require_untrained_sections(const config::Config& config,
                                      const train::RunOptions& options) const {
  options.require_binder_sections(config);
}

std::string Task::table(const std::vector<report::RunResult>& runs,
                        const report::TableOptions& options) const {
  return report::make_table(runs, options);
}

void Task::figures(const FigureOptions&) const {
  throw Error("skinlab figure: the " + name() + " task draws no figures");
}

namespace {

const std::string& option_text(const std::map<std::string, std::string>& values,
                               const std::string& name) {
  const auto it = values.find(name);
  if (it == values.end()) throw Error("--" + name + ": needs a value");
  return it->second;
}

std::map<std::string, std::shared_ptr<Task>>& instances() {
  static std::map<std::string, std::shared_ptr<Task>> tasks;
  return tasks;
}

/// The option's value parsed whole by `parse` (std::stoi, std::stod); Error saying `what` it
/// expected otherwise.
template <class T, class Parse>
T parse_option(const std::map<std::string, std::string>& values, const std::string& name,
               const char* what, Parse parse) {
  const std::string& text = option_text(values, name);
  std::size_t used = 0;
  T value{};
  try {
    value = parse(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size()) {
    throw Error("--" + name + ": expected " + what + ", got '" + text + "'");
  }
  return value;
}

}  // namespace

int int_option(const std::map<std::string, std::string>& values, const std::string& name) {
  return parse_option<int>(values, name, "an integer",
                           [](const std::string& t, std::size_t* n) { return std::stoi(t, n); });
}

double double_option(const std::map<std::string, std::string>& values, const std::string& name) {
  return parse_option<double>(values, name, "a number",
                              [](const std::string& t, std::size_t* n) { return std::stod(t, n); });
}

std::string string_option(const std::map<std::string, std::string>& values, const std::string& name,
                          const std::string& fallback) {
  const auto it = values.find(name);
  return it == values.end() ? fallback : it->second;
}

const Task& get(const std::string& name) {
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = instances().find(name);
  if (it == instances().end()) {
    it = instances().emplace(name, task_registry().create(name, config::Node())).first;
  }
  return *it->second;
}

std::vector<const Task*> all() {
  std::vector<const Task*> out;
  for (const std::string& name : task_registry().keys()) out.push_back(&get(name));
  return out;
}

const Task& of(const config::Config& config) {
  const config::Node key = config.root()["task"];
  if (!key.exists()) return get("skinning");
  const std::string name = key.as<std::string>();
  if (!task_registry().contains(name)) key.fail(task_registry().unknown_key_message(name));
  return get(name);
}

const Task& of_run(const RunDir& run) { return of(config::Config::load(run.file("config.yaml"))); }

void require_data_parallel(const Task& task, const std::string& source, const std::string& what,
                           const std::string& instead) {
  if (task.data_parallel()) return;
  std::vector<std::string> names;
  for (const Task* t : all()) {
    if (t->data_parallel()) names.push_back(t->name());
  }
  std::string owners;
  for (std::size_t i = 0; i < names.size(); ++i) {
    owners += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  }
  throw Error(source + ": " + what + " is the " + owners + (names.size() == 1 ? " task's" : " tasks'") +
              "; a " + task.name() + " run " + instead);
}

std::unique_ptr<TaskTrainer> make_trainer(const config::Config& config, train::World* world) {
  const train::RunOptions options = train::RunOptions::from(config);
  const Task& task = get(options.task);
  if (!task.data_parallel()) {
    if (world != nullptr && world->distributed()) {
      require_data_parallel(task, config.source(), "data-parallel training (--nproc, WORLD_SIZE)",
                            "trains in one process");
    }
    if (options.train.batch != 1) {
      throw ConfigError(config.source() + ": train.batch (characters per step) is for tasks "
                        "that train data-parallel; the " + task.name() + " task has its own batches");
    }
  }
  return task.trainer(config, task.data_parallel() ? world : nullptr);
}

eval::EvalReport evaluate_run(const RunDir& run, const eval::EvalOptions& options) {
  const config::Config config = config::Config::load(run.file("config.yaml"), options.overrides);
  const Task& task = of(config);
  if (options.world != nullptr && options.world->distributed()) {
    require_data_parallel(task, run.path().string(), "sharded evaluation",
                          "is evaluated in one process");
  }
  return task.evaluate(run, options);
}

std::string table_text(const std::vector<report::RunResult>& runs,
                       const report::TableOptions& options) {
  if (runs.empty()) return report::make_table(runs, options);
  return get(runs.front().task).table(runs, options);
}

}  // namespace skinlab::task

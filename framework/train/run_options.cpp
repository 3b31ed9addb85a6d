#include "framework/train/run_options.hpp"

#include <cmath>
#include <map>

#include "framework/binders/binder.hpp"
#include "framework/core/registry.hpp"
#include "framework/losses/loss.hpp"
#include "framework/task/task.hpp"

namespace skinlab::train {

DataOptions DataOptions::from(const config::Node& node) {
  DataOptions o;
  config::Fields f(node, "the data section", {});
  f.required("file", o.file).check(!o.file.empty(), "file", "must not be empty");
  f.optional("split", o.split).check(!o.split.empty(), "split", "must not be empty");
  f.optional("distance", o.distance);
  f.optional("val_sources", o.val_sources);
  if (!distance_registry().contains(o.distance)) {
    node["distance"].fail(distance_registry().unknown_key_message(o.distance));
  }
  f.finish();
  return o;
}

TrainOptions TrainOptions::from(const config::Node& node) {
  TrainOptions o;
  config::Fields f(node, "the train section", {});
  f.optional("epochs", o.epochs).check(o.epochs >= 1, "epochs", "must be ≥ 1");
  f.optional("lr", o.lr).check(std::isfinite(o.lr) && o.lr > 0, "lr", "must be a positive number");
  f.optional("weight_decay", o.weight_decay)
      .check(std::isfinite(o.weight_decay) && o.weight_decay >= 0, "weight_decay",
             "must be a number ≥ 0");
  f.optional("patience", o.patience)
      .check(o.patience >= 0, "patience", "must be ≥ 0 (0 disables early stopping)");
  f.optional("min_delta", o.min_delta)
      .check(std::isfinite(o.min_delta) && o.min_delta >= 0, "min_delta", "must be a number ≥ 0");
  f.optional("max_characters_per_epoch", o.max_characters_per_epoch)
      .check(o.max_characters_per_epoch >= 0, "max_characters_per_epoch",
             "must be ≥ 0 (0 = every training character)");
  f.optional("batch", o.batch).check(o.batch >= 1, "batch", "must be ≥ 1 character per step");
  f.optional("log_every", o.log_every)
      .check(o.log_every >= 0, "log_every", "must be ≥ 0 (0 = one line per epoch)");
  f.finish();
  return o;
}

RunOptions RunOptions::from(const config::Config& config) {
  RunOptions o;
  const config::Node root = config.root();
  config::Fields f(root, "the experiment config", {});
  f.required("experiment", o.experiment)
      .check(!o.experiment.empty(), "experiment", "must not be empty");
  f.optional("description", o.description);
  f.optional("seed", o.seed).check(o.seed >= 0, "seed", "must be ≥ 0");
  f.optional("threads", o.threads).check(o.threads >= 0, "threads", "must be ≥ 0 (0 = every hardware thread)");
  f.optional("results_dir", o.results_dir)
      .check(!o.results_dir.empty(), "results_dir", "must not be empty");
  f.optional("task", o.task)
      .check(task_registry().contains(o.task), "task", task_registry().unknown_key_message(o.task));
  const task::Task& task = task::get(o.task);
  // Every task's own section is read here, so that one in another task's config is named.
  std::map<std::string, config::Node> task_sections;
  for (const task::Task* t : task::all()) {
    if (!t->section().empty()) task_sections[t->section()] = f.section(t->section());
  }
  o.model = f.section("model");
  o.binder = f.section("binder");
  o.losses = f.section("losses");
  o.metrics = f.section("metrics");
  o.data_node = f.section("data");
  const config::Node train = f.section("train");
  f.finish();

  for (const task::Task* t : task::all()) {
    if (t->section().empty()) continue;
    const config::Node& node = task_sections.at(t->section());
    if (t == &task) {
      o.task_section = node;
    } else if (node.exists()) {
      node.fail("a '" + t->section() + "' section belongs to a config with task: " + t->name());
    }
  }
  if (o.model.exists()) task.check_model(o.model);
  if (o.binder.exists()) {
    if (o.model.exists()) {
      o.binder.fail("a config has a 'model' (a network to train) or a 'binder' (weights from "
                    "geometry alone), not both");
    }
    if (binders::is_reference_row(o.binder.required_type("binder"))) {
      binders::reference_row_prior(o.binder);  // validates its fields
    } else {
      binder_registry().create(o.binder);
    }
  }
  if (o.losses.exists()) losses::LossSum::from(o.losses);
  if (o.metrics.exists()) {
    if (!o.metrics.is_sequence()) o.metrics.fail("expected a list of metrics");
    for (std::size_t i = 0; i < o.metrics.size(); ++i) metric_registry().create(o.metrics[i]);
  }
  if (o.data_node.exists()) o.data = DataOptions::from(o.data_node);
  o.train = TrainOptions::from(train);
  return o;
}

const char* const kDataExample =
    "data: {file: <dataset .h5>, split: random, distance: hollow_dist}";

void require_sections(const config::Config& config, const char* what,
                      std::initializer_list<std::pair<const config::Node*, const char*>> sections) {
  for (const auto& [node, example] : sections) {
    if (!node->exists() || node->is_null()) {
      throw ConfigError(config.source() + ": " + what + " needs a '" +
                        std::string(example).substr(0, std::string(example).find(':')) +
                        "' section, e.g. " + example);
    }
  }
}

void RunOptions::require_training_sections(const config::Config& config) const {
  if (binder.exists()) {
    throw ConfigError(config.source() + ": a 'binder' is not trained; evaluate it with "
                      "`skinlab eval " + config.source() + " --split test`");
  }
  task::get(task).require_training_sections(config, *this);
}

void RunOptions::require_binder_sections(const config::Config& config) const {
  require_sections(config, "evaluating a config",
                   {{&binder, "binder: {type: geo_voxel}"}, {&data_node, kDataExample}});
}

}  // namespace skinlab::train

#include "framework/train/run_options.hpp"

#include "framework/core/registry.hpp"
#include "framework/losses/loss.hpp"

namespace skinlab::train {

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
  o.model = f.section("model");
  o.losses = f.section("losses");
  o.metrics = f.section("metrics");
  f.finish();

  if (o.model.exists()) model_registry().create(o.model);
  if (o.losses.exists()) losses::LossSum::from(o.losses);
  if (o.metrics.exists()) {
    if (!o.metrics.is_sequence()) o.metrics.fail("expected a list of metrics");
    for (std::size_t i = 0; i < o.metrics.size(); ++i) metric_registry().create(o.metrics[i]);
  }
  return o;
}

}  // namespace skinlab::train

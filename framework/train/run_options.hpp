#pragma once
/// \file
/// The top level of an experiment config. Every key a config may have at the top level is read
/// here; plug-in sections are validated by constructing them through their registries, so a
/// misspelled option or unknown `type:` anywhere is reported before any work starts.
///
///     experiment: heterskinnet        # results go to <results_dir>/<experiment>/<run_id>/
///     description: ...                # free text, saved with the run
///     seed: 0                         # every random choice of the run derives from it
///     threads: 0                      # libtorch intra-op threads; 0 = every hardware thread
///     results_dir: results
///     model: {type: ...}              # `model` registry
///     losses: [{type: kl, weight: 1}] # `loss` registry, weighted sum
///     metrics: [{type: ...}]          # `metric` registry

#include <cstdint>
#include <string>

#include "framework/core/config.hpp"

namespace skinlab::train {

struct RunOptions {
  std::string experiment;
  std::string description;
  std::int64_t seed = 0;
  int threads = 0;
  std::string results_dir = "results";
  config::Node model;    ///< missing when the config has no model section
  config::Node losses;   ///< missing when the config has no losses section
  config::Node metrics;  ///< missing when the config has no metrics section

  /// Reads and validates the whole config (see the file comment). Throws ConfigError or
  /// RegistryError with the file, line and key path of the first problem.
  static RunOptions from(const config::Config& config);
};

}  // namespace skinlab::train

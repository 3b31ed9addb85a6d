#pragma once
// Prepares a dataset config on the bundled real 0 A.D. subset (datasets/zeroad/bundled) for
// tests: its output redirected, two threads, no progress output, extra overrides appended.

#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/data/prepare.hpp"

namespace skinlab::testing {

/// `config` relative to the source tree (e.g. "configs/datasets/zeroad_bundled.yaml") with its
/// sources replaced by the bundled subset, written to `output`, extra overrides appended.
inline data::PrepareConfig bundled_config(const std::string& config, const std::string& output,
                                          const std::vector<std::string>& extra = {}) {
  const std::string source = std::string(SKINLAB_SOURCE_DIR);
  std::vector<std::string> overrides = {
      "output=" + output, "sources=[{type: zeroad, path: " + source + "/datasets/zeroad/bundled}]"};
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  return data::PrepareConfig::from(config::Config::load(source + "/" + config, overrides));
}

/// bundled_config(...) prepared on two threads without progress output, and read back.
inline data::Dataset prepare_bundled(const std::string& config, const std::string& output,
                                     const std::vector<std::string>& extra = {}) {
  data::PrepareOptions quiet;
  quiet.threads = 2;
  quiet.progress = false;
  data::prepare_dataset(bundled_config(config, output, extra), quiet);
  return data::read_dataset(output);
}

}  // namespace skinlab::testing

#pragma once
// Prepares a dataset config on the bundled real 0 A.D. subset (datasets/zeroad/bundled) for
// tests: its output redirected, two threads, no progress output, extra overrides appended.

#include <nlohmann/json.hpp>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/data/prepare.hpp"
#include "framework/data/preprocess.hpp"
#include "framework/data/source.hpp"

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

/// The characters of the bundled 0 A.D. subset that the evaluation of the model in `model_dir`
/// (its eval_test.json) scored, as its builder reads them from the game files and in the frame
/// the model's dataset was prepared in: mirrored into the right-handed frame
/// (datasets::make_right_handed) when the model's preparation.yaml sets
/// `preprocess.right_handed`, as `prepare` did for its evaluation and `skinlab export` does for a
/// user's file.
inline std::vector<datasets::SourceCharacter> bundled_test_characters(
    const std::filesystem::path& model_dir) {
  const nlohmann::json eval = nlohmann::json::parse(read_file(model_dir / "eval_test.json"));
  std::set<std::string> test;
  for (const auto& c : eval.at("per_character")) test.insert(c.at("character").get<std::string>());
  const bool right_handed =
      data::PreprocessOptions::from(
          config::Config::load((model_dir / "preparation.yaml").string()).root()["preprocess"])
          .right_handed;
  const data::PrepareConfig config =
      bundled_config("configs/datasets/zeroad_bundled.yaml", "unused.h5");
  std::vector<datasets::Excluded> excluded;
  std::vector<datasets::SourceCharacter> characters;
  for (const auto& node : config.sources)
    for (auto& source : dataset_registry().create(node)->read(excluded))
      if (test.count(source.character.name)) {
        if (right_handed) datasets::make_right_handed(source);
        characters.push_back(std::move(source));
      }
  return characters;
}

}  // namespace skinlab::testing

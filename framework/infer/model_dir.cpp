#include "framework/infer/model_dir.hpp"

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/data/h5.hpp"

namespace skinlab::infer {

namespace fs = std::filesystem;

fs::path default_model() {
  const auto is_model = [](const fs::path& dir) { return fs::is_regular_file(dir / "config.yaml"); };
  if (const char* env = std::getenv("SKINLAB_MODEL"); env != nullptr && *env != '\0') {
    if (!is_model(env)) {
      throw Error(std::string("SKINLAB_MODEL=") + env +
                  ": not a model directory (no config.yaml); unset it to use the bundled model");
    }
    spdlog::info("model {} (SKINLAB_MODEL)", env);
    return env;
  }
  std::vector<std::string> tried;
  if (const fs::path data = installed_data_dir(); !data.empty()) {
    const fs::path installed = data / "models" / "heterskinnet";
    if (is_model(installed)) {
      spdlog::info("model {} (installed with the program)", installed.string());
      return installed;
    }
    tried.push_back(installed.string());
  }
  const bool build_tree = running_from_build_tree();
  if (build_tree) {
    const fs::path bundled = source_dir() / "results" / "bundled" / "heterskinnet";
    if (is_model(bundled)) {
      spdlog::info("model {} (the source tree of this build)", bundled.string());
      return bundled;
    }
    tried.push_back(bundled.string());
  }
  std::string where;
  for (const auto& dir : tried) where += (where.empty() ? "" : ", ") + dir;
  throw Error("no model: give --model DIR or set SKINLAB_MODEL; the bundled model is not in " +
              (where.empty() ? std::string("any place (the program's own path is unknown)") : where) +
              (build_tree ? "" : " (a program outside its build tree does not use the source tree)"));
}

fs::path model_config_file(const fs::path& dir, const std::string& hint) {
  fs::path file = dir / "config.yaml";
  if (!fs::is_directory(dir) || !fs::exists(file)) {
    throw IoError(dir.string() + ": not a model directory (no config.yaml); " + hint);
  }
  return file;
}

std::string read_preparation(const fs::path& dir, const std::string& data_file) {
  const fs::path own = dir / "preparation.yaml";
  if (fs::exists(own)) return read_file(own);
  if (data_file.empty()) {
    throw IoError(dir.string() + ": no preparation.yaml and no data.file in config.yaml");
  }
  const fs::path data = data_file;
  if (!fs::exists(data)) {
    throw IoError(dir.string() + ": no preparation.yaml, and the run's dataset " + data.string() +
                  " (data.file), whose preprocessing the model needs, does not exist; prepare "
                  "it again or predict with a bundled model (skinlab bundle)");
  }
  const std::unique_ptr<data::H5Reader> reader = data::open_dataset_file(data);
  if (!reader->has_attribute("/", "preparation")) {
    throw IoError(data.string() + ": no 'preparation' attribute (written by skinlab prepare)");
  }
  return reader->read_attribute("/", "preparation");
}

Preparation parse_preparation(const std::string& yaml, const fs::path& file, const fs::path& dir,
                              const std::string& distance, const std::string& prior) {
  const config::Config preparation = config::Config::parse(yaml, file.string());
  Preparation p;
  try {
    p.preprocess = data::keep_prior(
        data::PreprocessOptions::from(preparation.root()["preprocess"]), prior);
  } catch (const ConfigError& e) {
    throw ConfigError(dir.string() + ": " + e.what());
  }
  const config::Node distances = preparation.root()["distances"];
  for (std::size_t i = 0; i < distances.size(); ++i) {
    const config::Node node = distances[i];
    if (node.required_type("distance") != distance) continue;
    p.distances.push_back({distance, distance_registry().create(node)});
  }
  if (p.distances.empty()) {
    throw ConfigError(dir.string() + ": the model reads distance '" + distance +
                      "', which its preparation does not list");
  }
  return p;
}

Preparation load_preparation(const fs::path& dir, const std::string& data_file,
                             const std::string& distance, const std::string& prior) {
  return parse_preparation(read_preparation(dir, data_file), dir / "preparation.yaml", dir,
                           distance, prior);
}

}  // namespace skinlab::infer

#include "framework/infer/model_dir.hpp"

#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/h5.hpp"

namespace skinlab::infer {

namespace fs = std::filesystem;

fs::path default_model() { return source_dir() / "results" / "bundled" / "heterskinnet"; }

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
  const data::H5Reader reader(data);
  if (!reader.has_attribute("/", "preparation")) {
    throw IoError(data.string() + ": no 'preparation' attribute (written by skinlab prepare)");
  }
  return reader.read_attribute("/", "preparation");
}

Preparation parse_preparation(const std::string& yaml, const fs::path& file, const fs::path& dir,
                              const std::string& distance) {
  const config::Config preparation = config::Config::parse(yaml, file.string());
  Preparation p;
  p.preprocess = data::PreprocessOptions::from(preparation.root()["preprocess"]);
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

}  // namespace skinlab::infer

#include "framework/infer/binder_engine.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>

#include "framework/binders/binder.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/core/timing.hpp"
#include "framework/infer/model_dir.hpp"

namespace skinlab::infer {

namespace fs = std::filesystem;

namespace {

/// The binder type of `spec` and its options node (empty for a bare key); `config` owns the tree
/// the node views.
struct BinderSpec {
  config::Config config;
  config::Node node;
  std::string type;
};

BinderSpec read_spec(const std::string& spec) {
  const bool file = fs::is_regular_file(spec);
  const bool key = !file && !spec.empty() && std::all_of(spec.begin(), spec.end(), [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
  });
  // A registry key alone keeps its default options: the node stays empty (an empty map).
  BinderSpec out{config::Config::parse("{}", "--binder"), {}, key ? spec : ""};
  if (file) {
    out.config = config::Config::load(spec);
    out.node = out.config.root()["binder"];
    if (!out.node.is_map()) {
      throw ConfigError(spec + ": no binder: section (give a config of a non-learned method, e.g. "
                        "configs/baselines/bone_heat.yaml)");
    }
    out.type = out.node.required_type("binder");
  } else if (!key) {
    try {
      out.config = config::Config::parse(spec, "--binder");
    } catch (const ConfigError& e) {
      throw ConfigError("--binder '" + spec + "': give a binder type (bone_heat), YAML like "
                        "'{type: bone_heat, closest: blender}', or a config file with a binder: "
                        "section (" + e.what() + ")");
    }
    out.node = out.config.root();
    out.type = out.node.required_type("binder");
  }
  if (binders::is_reference_row(out.type)) {
    throw ConfigError("--binder '" + spec + "': '" + out.type + "' is a reference row of skinlab "
                      "eval, computed from a dataset file's weights; it cannot skin a new character");
  }
  return out;
}

}  // namespace

BinderEngine BinderEngine::load(const std::string& spec, const fs::path& dir) {
  const BinderSpec binder = read_spec(spec);
  BinderEngine e;
  e.type_ = binder.type;
  e.binder_ = binder_registry().create(e.type_, binder.node);
  const fs::path config_file = model_config_file(
      dir, "--binder takes its preparation from a run directory or a bundled model");
  const config::Node data = config::Config::load(config_file).root()["data"];
  const std::string data_file = data.has("file") ? data["file"].as<std::string>() : "";
  const std::string distance = data["distance"].as<std::string>();
  // Without the model's priors (load_preparation's empty `prior`): the binder is the method.
  e.preparation_ = load_preparation(dir, data_file, distance);
  e.description_ = fmt::format("binder '{}' on the preparation of {}", e.type_, dir.string());
  return e;
}

Prediction BinderEngine::predict(const geometry::Character& character,
                                 const PredictOptions& options, StageTimes* times) const {
  PreparedInput input = prepare_to_predict(character, preparation_, options, times);
  const auto start = std::chrono::steady_clock::now();
  const data::PreparedCharacter& c = input.prepared;
  const std::string method = fmt::format("binder '{}'", type_);
  const Eigen::MatrixXd W =
      binders::bind_checked(*binder_, c.mesh(), c.rig(), fmt::format("{} on '{}'", method, c.name));
  if (times != nullptr) times->network += seconds_since(start);
  return finish_bone_weights(std::move(input), distance(), W, options.prune, method, times);
}

}  // namespace skinlab::infer

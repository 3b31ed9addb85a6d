#include "framework/infer/predict_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <map>
#include <optional>
#include <string>

#include "framework/core/atomic_file.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/progress.hpp"
#include "framework/core/timing.hpp"
#include "framework/infer/model_dir.hpp"
#include "framework/infer/outputs.hpp"

namespace skinlab::infer {

namespace fs = std::filesystem;

Eigen::Vector3d up_axis(const std::string& up) {
  if (up == "y") return Eigen::Vector3d::UnitY();
  if (up == "z") return Eigen::Vector3d::UnitZ();
  throw Error("--up must be y or z, got '" + up + "'");
}

namespace {

/// The counts of one predicted character (a row of the batch summary).
struct CharacterResult {
  int vertices = 0;
  int joints = 0;
  int bones = 0;
};

/// Reads and checks `input` (with `rig`, or the rig text beside an OBJ): the cheap errors, so
/// the one-file form reports them before it loads the model. Errors name the file (and rig).
geometry::Character load_input(const fs::path& input, fs::path rig, const PredictArgs& args,
                               const PredictOptions& options, StageTimes& times) {
  const auto start = std::chrono::steady_clock::now();
  if (rig.empty()) {
    rig = geometry::rig_beside(input);
    if (!rig.empty()) spdlog::info("{}: rig text {} (next to it)", input.string(), rig.string());
  }
  // Only comparing needs the input's weights whole; the prediction itself ignores them.
  const geometry::SkinLines skin = args.compare || args.error_map
                                       ? geometry::SkinLines::require
                                       : geometry::SkinLines::ignore_mismatch;
  geometry::Character character = geometry::load_character(input, rig, skin);
  try {
    check_predictable(character, options);
  } catch (const Error& e) {
    throw Error((rig.empty() ? input.string() : input.string() + " with " + rig.string()) + ": " +
                e.what());
  }
  if ((args.compare || args.error_map) && !character.has_weights()) {
    throw Error(input.string() + ": " + (args.compare ? "--compare-to-input" : "--error-map") +
                ", but the input carries no skin weights");
  }
  times.load = seconds_since(start);
  return character;
}

/// Predicts `input`'s weights and writes them to `outputs` (with the hooks before and after),
/// printing every file written and one line about the character: the whole work on one
/// character after its loading, shared by the one-file form and every step of a batch.
CharacterResult predict_and_write(const geometry::Character& input,
                                  const std::vector<fs::path>& outputs, const PredictArgs& args,
                                  const PredictOptions& options, const PredictEngine& engine,
                                  const PredictHooks& hooks, StageTimes& times) {
  const Prediction p = engine.predict(input, options, &times);
  if (hooks.before_write) hooks.before_write(input, p, engine, args);
  const auto start = std::chrono::steady_clock::now();
  for (const auto& out : outputs) {
    write_prediction(out, input, p, engine.description(), engine.distance(), args.prune);
    std::cout << "wrote " << out.string() << "\n";
  }
  times.export_ = seconds_since(start);
  if (hooks.after_write) hooks.after_write(p, args);
  std::cout << fmt::format("{}: {} vertices ({} prepared), {} joints, {} bones; {:.3f} s\n",
                           input.name, input.mesh.num_vertices(), p.prepared.num_vertices(),
                           input.skeleton.num_joints(), p.prepared.num_bones(), times.total());
  return {input.mesh.num_vertices(), input.skeleton.num_joints(), p.prepared.num_bones()};
}

void print_timings(const StageTimes& times, double model_seconds) {
  std::cout << fmt::format(
      "stages (s): load {:.4f}, normalise {:.4f}, distance {:.4f}, graph {:.4f}, network "
      "{:.4f}, map back {:.4f}, export {:.4f}; model loading {:.4f}; peak memory {:.0f} MiB\n",
      times.load, times.normalise, times.distance, times.graph, times.network, times.map_back,
      times.export_, model_seconds, peak_memory_mib());
}

PredictOptions predict_options(const PredictArgs& args) {
  PredictOptions options;
  options.prune = args.prune;
  options.up = up_axis(args.up);
  options.max_vertices = args.max_vertices;
  return options;
}

/// The model of `--model`, or the bundled one, with its load time.
std::unique_ptr<PredictEngine> load_model(const PredictArgs& args, const PredictHooks& hooks,
                                          double& seconds) {
  const auto start = std::chrono::steady_clock::now();
  const fs::path dir = args.model.empty() ? default_model() : fs::path(args.model);
  std::unique_ptr<PredictEngine> engine = hooks.load(dir, args);
  seconds = seconds_since(start);
  spdlog::info("model: {}", engine->description());
  return engine;
}

/// `skinlab predict <input> --out FILE...`: one character, every error fatal.
int run_one(const PredictArgs& args, const PredictHooks& hooks) {
  if (args.out.empty() && args.render.empty()) {
    throw Error("predict: give at least one --out file or --render");
  }
  const fs::path input = args.inputs.front();
  if (fs::is_directory(input) || args.inputs.front().rfind('@', 0) == 0) {
    throw Error(args.inputs.front() + ": a directory or list of characters needs --out-dir DIR");
  }
  std::vector<fs::path> outputs(args.out.begin(), args.out.end());
  for (const auto& out : outputs) output_kind(out);  // before any work
  if (!args.render.empty() && fs::path(args.render).extension() != ".png") {
    throw Error(args.render + ": --render writes a .png file");
  }
  if (args.error_map && args.render.empty()) throw Error("--error-map needs --render out.png");
  const PredictOptions options = predict_options(args);

  // The input first: its errors are the cheap ones.
  StageTimes times;
  const geometry::Character character = load_input(input, args.rig, args, options, times);
  double model_seconds = 0;
  const std::unique_ptr<PredictEngine> engine = load_model(args, hooks, model_seconds);
  predict_and_write(character, outputs, args, options, *engine, hooks, times);
  if (args.timings) print_timings(times, model_seconds);
  return 0;
}

/// The character files `inputs` name, in order: a file as it is, a directory's character files
/// sorted by name, and the lines of `@list.txt` (blank lines and `#` comments skipped; paths
/// relative to the list file), each a file or a directory. A directory without character files
/// or an unreadable list is an Error naming it.
std::vector<fs::path> expand_inputs(const std::vector<std::string>& inputs) {
  std::vector<fs::path> files;
  const auto add = [&](const fs::path& path) {
    if (!fs::is_directory(path)) {
      files.push_back(path);
      return;
    }
    std::vector<fs::path> found;
    for (const auto& entry : fs::directory_iterator(path)) {
      if (entry.is_regular_file() && geometry::is_character_file(entry.path())) {
        found.push_back(entry.path());
      }
    }
    if (found.empty()) {
      throw Error(path.string() + ": a directory without character files (OBJ, FBX, glTF/GLB, "
                                  "DAE, B3D, IQM, SMD, X, MD5)");
    }
    std::sort(found.begin(), found.end());
    files.insert(files.end(), found.begin(), found.end());
  };
  for (const std::string& input : inputs) {
    if (input.rfind('@', 0) != 0) {
      add(input);
      continue;
    }
    const fs::path list = input.substr(1);
    const std::string text = read_file(list);
    std::size_t at = 0, count = 0;
    while (at < text.size()) {
      std::size_t end = text.find('\n', at);
      if (end == std::string::npos) end = text.size();
      std::string line = text.substr(at, end - at);
      at = end + 1;
      line.erase(0, line.find_first_not_of(" \t\r"));
      line.erase(line.find_last_not_of(" \t\r") + 1);
      if (line.empty() || line[0] == '#') continue;
      const fs::path path(line);
      add(path.is_absolute() ? path : list.parent_path() / path);
      ++count;
    }
    if (count == 0) throw Error(list.string() + ": the list names no character");
  }
  return files;
}

/// `DIR/<stem>.<ext>` of `input` for `--format`.
fs::path batch_output(const fs::path& dir, const fs::path& input, const std::string& format) {
  static const std::map<std::string, std::string> kSuffix = {
      {"glb", ".glb"}, {"gltf", ".gltf"}, {"rig", "_rig.txt"}, {"h5", ".h5"}};
  return dir / (input.stem().string() + kSuffix.at(format));
}

/// `skinlab predict <input>... --out-dir DIR`: the model once, then every character; one that
/// fails is reported and skipped.
int run_batch(const PredictArgs& args, const PredictHooks& hooks) {
  if (!args.out.empty()) throw Error("predict: --out-dir writes DIR/<stem>.<ext>; --out is for one input");
  if (!args.rig.empty()) {
    throw Error("predict: --rig goes with one OBJ input; in a batch each OBJ takes the rig text "
                "next to it (<stem>_rig.txt, <stem>.txt or <id>_ori_rig.txt)");
  }
  if (!args.render.empty() || args.error_map) {
    throw Error("predict: --render and --error-map draw one character; use them with --out");
  }
  const PredictOptions options = predict_options(args);
  const fs::path dir = args.out_dir;
  // Every input and its output, and every clash between them, before any work.
  const std::vector<fs::path> inputs = expand_inputs(args.inputs);
  std::vector<fs::path> outputs;
  std::map<fs::path, fs::path> writer;  // output -> the input that writes it
  for (const fs::path& input : inputs) {
    const fs::path out = batch_output(dir, input, args.format);
    const auto [it, fresh] = writer.emplace(out.lexically_normal(), input);
    if (!fresh) {
      throw Error(fmt::format("predict: {} and {} would both write {}; rename one or predict them "
                              "in separate runs",
                              it->second.string(), input.string(), out.string()));
    }
    outputs.push_back(out);
  }
  std::map<fs::path, fs::path> input_at;  // where each existing input file really is
  for (const fs::path& input : inputs) {
    std::error_code missing;  // a missing input fails in its turn
    const fs::path real = fs::weakly_canonical(input, missing);
    if (!missing) input_at.emplace(real, input);
  }
  for (const fs::path& out : outputs) {
    const auto it = input_at.find(fs::weakly_canonical(out));
    if (it != input_at.end()) {
      throw Error(fmt::format("predict: {} would replace the input {}; choose another --out-dir",
                              out.string(), it->second.string()));
    }
  }
  fs::create_directories(dir);

  double model_seconds = 0;
  const std::unique_ptr<PredictEngine> engine = load_model(args, hooks, model_seconds);
  std::vector<std::optional<CharacterResult>> results(inputs.size());  // empty: failed
  std::vector<double> seconds(inputs.size());  // load, prediction and export (or failure)
  std::vector<std::string> failed;
  std::optional<Progress> progress;
  if (::isatty(STDERR_FILENO)) progress.emplace("predict", inputs.size());
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const auto start = std::chrono::steady_clock::now();
    try {
      StageTimes times;
      const geometry::Character character = load_input(inputs[k], {}, args, options, times);
      results[k] = predict_and_write(character, {outputs[k]}, args, options, *engine, hooks, times);
      if (args.timings) print_timings(times, model_seconds);
    } catch (const std::exception& e) {
      const std::string what = e.what();
      const std::string name = inputs[k].string();
      spdlog::error("{} (skipped)", what.rfind(name, 0) == 0 ? what : name + ": " + what);
      failed.push_back(name);
    }
    seconds[k] = seconds_since(start);
    if (progress) progress->tick();
  }
  if (progress) progress->finish();

  std::size_t width = 4;
  for (const fs::path& input : inputs) width = std::max(width, input.string().size());
  std::cout << fmt::format("\n{:<{}}  {:<6}  {:>8}  {:>6}  {:>5}  {:>8}\n", "file", width,
                           "status", "vertices", "joints", "bones", "seconds");
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const auto count = [&](int CharacterResult::*field) {
      return results[k] ? std::to_string((*results[k]).*field) : std::string("-");
    };
    std::cout << fmt::format("{:<{}}  {:<6}  {:>8}  {:>6}  {:>5}  {:>8.3f}\n", inputs[k].string(),
                             width, results[k] ? "ok" : "failed", count(&CharacterResult::vertices),
                             count(&CharacterResult::joints), count(&CharacterResult::bones),
                             seconds[k]);
  }
  std::cout << fmt::format("{} of {} characters written to {}\n", inputs.size() - failed.size(),
                           inputs.size(), dir.string());
  if (!failed.empty()) {
    std::string names;
    for (const auto& name : failed) names += (names.empty() ? "" : ", ") + name;
    throw Error(fmt::format("predict: {} of {} characters failed: {}", failed.size(), inputs.size(),
                            names));
  }
  return 0;
}

}  // namespace

int run_predict(const PredictArgs& args, const PredictHooks& hooks) {
  if (!args.out_dir.empty()) return run_batch(args, hooks);
  if (args.inputs.size() > 1) {
    throw Error("predict: " + std::to_string(args.inputs.size()) +
                " inputs need --out-dir DIR (each writes DIR/<stem>.<ext>)");
  }
  return run_one(args, hooks);
}

void add_predict_options(CLI::App& cmd, PredictArgs& args) {
  cmd.add_option("inputs", args.inputs,
                 "character files (FBX, glTF/GLB, DAE, IQM, B3D, ... or OBJ with its rig text: "
                 "--rig, or next to it as <stem>_rig.txt, <stem>.txt or, for RigNet's "
                 "<id>_remesh.obj, <id>_ori_rig.txt); with --out-dir also directories (their "
                 "character files) and @list.txt (one path a line, relative to the list)")
      ->required();
  cmd.add_option("--rig", args.rig, "RigNet rig text file of an OBJ mesh (its skeleton; skin "
                                     "lines that do not fit the mesh are a warning)");
  cmd.add_option("--model", args.model,
                 "run directory or bundled model (default: $SKINLAB_MODEL, else the model "
                 "installed with the program, <prefix>/share/skinlab/models/heterskinnet, else "
                 "in a build tree results/bundled/heterskinnet)");
  cmd.add_option("--out", args.out, "output file: .glb, .gltf, _rig.txt or .h5 (repeatable)");
  cmd.add_option("--out-dir", args.out_dir,
                 "many inputs: write DIR/<stem>.<ext> for each; a failing input is reported and "
                 "skipped, the exit status is 1 if any failed");
  cmd.add_option("--format", args.format, "with --out-dir: glb, gltf, rig (_rig.txt) or h5")
      ->check(CLI::IsMember({"glb", "gltf", "rig", "h5"}))
      ->capture_default_str();
  cmd.add_option("--prune", args.prune,
                 "drop weights below this fraction of the row maximum (HeterSkinNet Sec. 4.5)")
      ->capture_default_str();
  cmd.add_option("--up", args.up, "up axis of the input, y or z")->capture_default_str();
  cmd.add_option("--max-vertices", args.max_vertices, "refuse inputs with more vertices")
      ->capture_default_str();
  cmd.add_flag("--timings", args.timings, "print the time of every stage");
}

}  // namespace skinlab::infer

/// \file
/// `skinlab predict <input> [--rig rig.txt] [--model DIR] --out FILE [--out FILE ...]`: skin
/// weights for one character with a trained model (framework/predict/predictor.hpp), written in
/// the input's own frame, vertex order and joint names:
///
///     .glb / .gltf   glTF 2.0 skin (geometry/gltf_export.hpp): joints, inverse bind matrices,
///                    JOINTS_0/WEIGHTS_0 with each vertex's 4 largest weights renormalised
///     _rig.txt       RigNet rig text (geometry/rig_io.hpp): every kept weight
///     .h5            the full #V×#B bone weights and #V×#J joint weights (file comment below)
///
/// Input: an OBJ with `--rig` (RigNet rig text) or with a rig text next to it
/// (geometry::rig_beside), or one file assimp reads with a skeleton (FBX, glTF/GLB, DAE, IQM,
/// B3D, ...). Weights in the input are ignored by the prediction, so `skin` lines of a rig text
/// that do not fit the mesh are one warning (geometry::SkinLines::ignore_mismatch); with
/// `--compare-to-input` or `--error-map` they must be valid and the model's metrics
/// (HeterSkinNet Sec. 4.3) against them are printed. Every output is checked before any work
/// starts and written whole (atomic rename), so a failure never leaves a partial file.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <iostream>
#include <map>
#include <string>

#include "framework/cli/commands.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/timing.hpp"
#include "framework/geometry/load_character.hpp"
#include "framework/predict/outputs.hpp"
#include "framework/predict/predictor.hpp"
#include "framework/report/plot.hpp"
#include "framework/report/skin_render.hpp"

namespace skinlab::cli {

namespace {

/// One line: the header, then " name value" per metric with 4 decimals (scripts/compare_blender
/// reads these lines).
void print_metrics(const std::string& header, const std::map<std::string, double>& values) {
  std::cout << header;
  for (const auto& [name, value] : values) std::cout << fmt::format(" {} {:.4f}", name, value);
  std::cout << "\n";
}

namespace fs = std::filesystem;

struct PredictArgs {
  std::string input;
  std::string rig;
  std::string model;
  std::string checkpoint = "best";
  std::vector<std::string> out;
  double prune = 0.25;
  int max_vertices = 50000;
  std::string up = "y";
  bool compare = false;
  bool timings = false;
  std::string render;
  bool error_map = false;
};

Eigen::Vector3d up_axis(const std::string& up) {
  if (up == "y") return Eigen::Vector3d::UnitY();
  if (up == "z") return Eigen::Vector3d::UnitZ();
  throw Error("--up must be y or z, got '" + up + "'");
}

int run(const PredictArgs& args) {
  using Clock = std::chrono::steady_clock;
  if (args.out.empty() && args.render.empty()) {
    throw Error("predict: give at least one --out file or --render");
  }
  for (const auto& out : args.out) predict::output_kind(out);  // before any work
  if (!args.render.empty() && fs::path(args.render).extension() != ".png") {
    throw Error(args.render + ": --render writes a .png file");
  }
  if (args.error_map && args.render.empty()) throw Error("--error-map needs --render out.png");
  const Eigen::Vector3d up = up_axis(args.up);

  predict::PredictOptions options;
  options.prune = args.prune;
  options.up = up;
  options.max_vertices = args.max_vertices;

  // The input first: its errors are the cheap ones.
  predict::StageTimes times;
  auto start = Clock::now();
  // Only comparing needs the input's weights whole; the prediction itself ignores them.
  const geometry::SkinLines skin = args.compare || args.error_map
                                       ? geometry::SkinLines::require
                                       : geometry::SkinLines::ignore_mismatch;
  geometry::Character input = geometry::load_character(args.input, args.rig, skin);
  try {
    predict::check_predictable(input, options);
  } catch (const Error& e) {
    throw Error((args.rig.empty() ? args.input : args.input + " with " + args.rig) + ": " +
                e.what());
  }
  times.load = seconds_since(start);
  if ((args.compare || args.error_map) && !input.has_weights()) {
    throw Error(args.input + ": " + (args.compare ? "--compare-to-input" : "--error-map") +
                ", but the input carries no skin weights");
  }

  const fs::path model_dir = args.model.empty() ? predict::default_model() : fs::path(args.model);
  start = Clock::now();
  const predict::Predictor predictor = predict::Predictor::load(model_dir, args.checkpoint);
  const double model_seconds = seconds_since(start);
  spdlog::info("model: {}", predictor.description());
  const predict::Prediction p = predictor.predict(input, options, &times);

  if (args.compare) {
    print_metrics(input.name + " against the input's weights:", predictor.compare(p));
  }

  start = Clock::now();
  for (const auto& out : args.out) {
    predict::write_prediction(out, input, p, predictor, args.prune);
    std::cout << "wrote " << out << "\n";
  }
  times.export_ = seconds_since(start);
  if (!args.render.empty()) {
    // In the normalised frame (Y up), at the prepared vertices, where the weights were made.
    const Eigen::MatrixXd truth =
        args.error_map ? Eigen::MatrixXd(p.prepared_truth.cast<double>()) : Eigen::MatrixXd();
    report::write_png(args.render,
                      report::render_skin(p.prepared.V, p.prepared.F,
                                          p.prepared_weights.cast<double>(), truth));
    std::cout << "wrote " << args.render << "\n";
  }

  std::cout << fmt::format("{}: {} vertices ({} prepared), {} joints, {} bones; {:.3f} s\n",
                           input.name, input.mesh.num_vertices(), p.prepared.num_vertices(),
                           input.skeleton.num_joints(), p.prepared.num_bones(), times.total());
  if (args.timings) {
    std::cout << fmt::format(
        "stages (s): load {:.4f}, normalise {:.4f}, distance {:.4f}, graph {:.4f}, network "
        "{:.4f}, map back {:.4f}, export {:.4f}; model loading {:.4f}; peak memory {:.0f} MiB\n",
        times.load, times.normalise, times.distance, times.graph, times.network, times.map_back,
        times.export_, model_seconds, peak_memory_mib());
  }
  return 0;
}

}  // namespace

Command add_predict(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "predict", "skin weights for one character with a trained model (glTF, rig text, HDF5)");
  auto args = std::make_shared<PredictArgs>();
  cmd->add_option("input", args->input,
                  "character file (FBX, glTF/GLB, DAE, IQM, B3D, ... or OBJ with its rig text: "
                  "--rig, or next to it as <stem>_rig.txt, <stem>.txt or, for RigNet's "
                  "<id>_remesh.obj, <id>_ori_rig.txt)")
      ->required();
  cmd->add_option("--rig", args->rig, "RigNet rig text file of an OBJ mesh (its skeleton; skin "
                                      "lines that do not fit the mesh are a warning)");
  cmd->add_option("--model", args->model,
                  "run directory or bundled model (default: results/bundled/heterskinnet)");
  cmd->add_option("--checkpoint", args->checkpoint, "best or last (run directories)")
      ->capture_default_str();
  cmd->add_option("--out", args->out, "output file: .glb, .gltf, _rig.txt or .h5 (repeatable)");
  cmd->add_option("--prune", args->prune,
                  "drop weights below this fraction of the row maximum (HeterSkinNet Sec. 4.5)")
      ->capture_default_str();
  cmd->add_option("--up", args->up, "up axis of the input, y or z")->capture_default_str();
  cmd->add_option("--max-vertices", args->max_vertices, "refuse inputs with more vertices")
      ->capture_default_str();
  cmd->add_flag("--compare-to-input", args->compare,
                "print the metrics against the weights the input carries (they must be valid)");
  cmd->add_flag("--timings", args->timings, "print the time of every stage");
  cmd->add_option("--render", args->render,
                  "draw the character coloured by its most influential bone (.png)");
  cmd->add_flag("--error-map", args->error_map,
                "with --render: add the per-vertex L1 error against the input's weights");
  return {cmd, [args] { return run(*args); }};
}

namespace {

/// `skinlab score <character> [--rig] --weights <other>`: the model's metrics of another
/// method's weights (RigNet rig text, or a glTF/any assimp file of the same mesh) against the
/// character's own (artist) weights, joints matched by name.
int run_score(const std::string& input, const std::string& rig, const std::string& weights,
              const std::string& model, bool allow_unweighted) {
  const geometry::Character truth = geometry::load_character(input, rig);
  if (!truth.has_weights()) throw Error(input + ": carries no skin weights to score against");
  const predict::OtherWeights other = predict::read_other_weights(weights, truth, input, allow_unweighted);
  const geometry::SparseWeights& mapped = other.weights;
  const int unweighted = other.unweighted;
  if (unweighted > 0) {
    std::cout << fmt::format("{}: {} of {} vertices have no weight; scored as predicting no bone "
                             "(their linear blend skinning puts them at the origin)\n",
                             weights, unweighted, mapped.rows());
  }
  const fs::path model_dir = model.empty() ? predict::default_model() : fs::path(model);
  const predict::Predictor predictor = predict::Predictor::load(model_dir);
  print_metrics(weights + " against the weights of " + input + ":", predictor.score(truth, mapped));
  return 0;
}

}  // namespace

Command add_score(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "score", "the paper's metrics of another method's weights against a character's own");
  auto input = std::make_shared<std::string>();
  auto rig = std::make_shared<std::string>();
  auto weights = std::make_shared<std::string>();
  auto model = std::make_shared<std::string>();
  cmd->add_option("input", *input, "character with its artist weights (assimp file or OBJ)")
      ->required();
  cmd->add_option("--rig", *rig, "RigNet rig text of an OBJ input");
  cmd->add_option("--weights", *weights, "weights to score: _rig.txt or a file of the same mesh")
      ->required();
  cmd->add_option("--model", *model,
                  "model whose preparation and metrics are used (default: the bundled one)");
  auto allow_unweighted = std::make_shared<bool>(false);
  cmd->add_flag("--allow-unweighted", *allow_unweighted,
                "score vertices the other method left without weight as predicting no bone "
                "instead of refusing the file");
  return {cmd, [=] { return run_score(*input, *rig, *weights, *model, *allow_unweighted); }};
}

Command add_bundle(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "bundle", "a self-contained model directory for skinlab predict from a trained run");
  auto run_dir = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto checkpoint = std::make_shared<std::string>("best");
  cmd->add_option("run", *run_dir, "run directory of skinlab train")->required();
  cmd->add_option("--out", *out, "new directory, e.g. results/bundled/heterskinnet")->required();
  cmd->add_option("--checkpoint", *checkpoint, "best or last")->capture_default_str();
  return {cmd, [run_dir, out, checkpoint] {
            predict::bundle(*run_dir, *out, *checkpoint);
            std::cout << "wrote " << *out << "\n";
            return 0;
          }};
}

}  // namespace skinlab::cli

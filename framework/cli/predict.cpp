/// \file
/// `skinlab predict <input> [--rig rig.txt] [--model DIR] --out FILE [--out FILE ...]`: skin
/// weights for one character with a trained model (framework/predict/predictor.hpp), written in
/// the input's own frame, vertex order and joint names:
///
///     .glb / .gltf   glTF 2.0 skin (geometry/gltf_export.hpp): joints, inverse bind matrices,
///                    JOINTS_0/WEIGHTS_0 with each vertex's 4 largest weights renormalised
///     _rig.txt       RigNet rig text (geometry/rig_io.hpp): every kept weight
///     .h5            the full #V×#B bone weights and #V×#J joint weights (infer/outputs.hpp)
///
/// `skinlab predict <input>... --out-dir DIR [--format glb|gltf|rig|h5]`: many characters in one
/// run, the model loaded once. The command line (inputs, options, batch, summary) is
/// infer/predict_command.hpp, shared with the Eigen-only `skinlab-predict`; this file adds what
/// needs libtorch's side: the model (predict::Predictor, `--checkpoint`), `--compare-to-input`,
/// `--render` and `--error-map`, `--binder` (a classical method's weights on the same
/// preparation, infer/binder_engine.hpp), and the commands `score`, `bundle` and
/// `export-parameters`.
///
/// Input: an OBJ with `--rig` (RigNet rig text) or with a rig text next to it
/// (geometry::rig_beside: `<stem>_rig.txt`, `<stem>.txt`, or `<id>_ori_rig.txt` for RigNet's
/// `<id>_remesh.obj`), or one file assimp reads with a skeleton (FBX, glTF/GLB, DAE, IQM, B3D,
/// ...). Weights in the input are ignored by the prediction, so `skin` lines of a rig text that
/// do not fit the mesh are one warning (geometry::SkinLines::ignore_mismatch); with
/// `--compare-to-input` or `--error-map` they must be valid and the model's metrics
/// (HeterSkinNet Sec. 4.3) against them are printed. Every output is checked before any work
/// starts and written whole (atomic rename), so a failure never leaves a partial file.

#include <fmt/format.h>

#include <iostream>
#include <map>
#include <memory>
#include <string>

#include "framework/cli/commands.hpp"
#include "framework/core/error.hpp"
#include "framework/geometry/load_character.hpp"
#include "framework/infer/binder_engine.hpp"
#include "framework/infer/model_dir.hpp"
#include "framework/infer/outputs.hpp"
#include "framework/infer/predict_command.hpp"
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

/// `--render` of the one-file form: the prepared mesh coloured by each vertex's most influential
/// bone (and `--error-map`'s L1 error against the input's weights).
void render_prediction(const predict::Prediction& p, const infer::PredictArgs& args) {
  if (args.render.empty()) return;
  // In the normalised frame (Y up), at the prepared vertices, where the weights were made.
  const Eigen::MatrixXd truth =
      args.error_map ? Eigen::MatrixXd(p.prepared_truth.cast<double>()) : Eigen::MatrixXd();
  report::write_png(args.render, report::render_skin(p.prepared.V, p.prepared.F,
                                                     p.prepared_weights.cast<double>(), truth));
  std::cout << "wrote " << args.render << "\n";
}

}  // namespace

Command add_predict(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "predict",
      "skin weights for characters with a trained model (glTF, rig text, HDF5): one input with "
      "--out FILE, or many with --out-dir DIR");
  auto args = std::make_shared<infer::PredictArgs>();
  infer::add_predict_options(*cmd, *args);
  cmd->add_option("--checkpoint", args->checkpoint, "best or last (run directories)")
      ->capture_default_str();
  cmd->add_flag("--compare-to-input", args->compare,
                "print the metrics against the weights the input carries (they must be valid)");
  cmd->add_option("--render", args->render,
                  "draw the character coloured by its most influential bone (.png)");
  cmd->add_flag("--error-map", args->error_map,
                "with --render: add the per-vertex L1 error against the input's weights");
  cmd->add_option("--binder", args->binder,
                  "weights of a classical method instead of the network, on the character "
                  "prepared as --model's inputs (pruned and mapped back alike): a binder type "
                  "(bone_heat, geo_voxel), YAML like '{type: bone_heat, closest: blender}', or a "
                  "config file with a binder: section");
  infer::PredictHooks hooks;
  hooks.load = [](const fs::path& dir,
                  const infer::PredictArgs& a) -> std::unique_ptr<infer::PredictEngine> {
    if (!a.binder.empty()) {
      return std::make_unique<infer::BinderEngine>(infer::BinderEngine::load(a.binder, dir));
    }
    return std::make_unique<predict::Predictor>(predict::Predictor::load(dir, a.checkpoint));
  };
  // --compare-to-input reads the model's metrics; with --binder the model is loaded for them
  // once, on the first comparison.
  auto metrics_model = std::make_shared<std::unique_ptr<predict::Predictor>>();
  hooks.before_write = [metrics_model](const geometry::Character& input,
                                       const predict::Prediction& p,
                                       const infer::PredictEngine& engine,
                                       const infer::PredictArgs& a) {
    if (!a.compare) return;
    const auto* predictor = dynamic_cast<const predict::Predictor*>(&engine);
    if (predictor == nullptr) {
      if (!*metrics_model) {
        const fs::path dir = a.model.empty() ? infer::default_model() : fs::path(a.model);
        *metrics_model =
            std::make_unique<predict::Predictor>(predict::Predictor::load(dir, a.checkpoint));
      }
      predictor = metrics_model->get();
    }
    print_metrics(input.name + " against the input's weights:", predictor->compare(p));
  };
  hooks.after_write = render_prediction;
  return {cmd, [args, hooks] { return infer::run_predict(*args, hooks); }};
}

namespace {

/// `skinlab score <character> [--rig] --weights <other>`: the model's metrics of another
/// method's weights (RigNet rig text, or a glTF/any assimp file of the same mesh) against the
/// character's own (artist) weights, joints matched by name.
int run_score(const std::string& input, const std::string& rig, const std::string& weights,
              const std::string& model, bool allow_unweighted) {
  const geometry::Character truth = geometry::load_character(input, rig);
  if (!truth.has_weights()) throw Error(input + ": carries no skin weights to score against");
  const infer::OtherWeights other = infer::read_other_weights(weights, truth, input, allow_unweighted);
  const geometry::SparseWeights& mapped = other.weights;
  const int unweighted = other.unweighted;
  if (unweighted > 0) {
    std::cout << fmt::format("{}: {} of {} vertices have no weight; scored as predicting no bone "
                             "(their linear blend skinning puts them at the origin)\n",
                             weights, unweighted, mapped.rows());
  }
  const fs::path model_dir = model.empty() ? infer::default_model() : fs::path(model);
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

Command add_export_parameters(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "export-parameters",
      "a model's parameters in the plain format skinlab-predict runs (docs/parameters.md)");
  auto model = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto checkpoint = std::make_shared<std::string>("best");
  cmd->add_option("model", *model, "bundled model or run directory")->required();
  cmd->add_option("--out", *out, "parameter file (default: MODEL/parameters.h5)");
  cmd->add_option("--checkpoint", *checkpoint, "best or last (run directories)")
      ->capture_default_str();
  return {cmd, [model, out, checkpoint] {
            const predict::Predictor predictor = predict::Predictor::load(*model, *checkpoint);
            const fs::path file = out->empty() ? fs::path(*model) / "parameters.h5" : fs::path(*out);
            predictor.write_parameters(file);
            std::cout << "wrote " << file.string() << "\n";
            return 0;
          }};
}

}  // namespace skinlab::cli

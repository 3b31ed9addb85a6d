#pragma once
/// \file
/// The command line of a predicting program, shared by `skinlab predict` (libtorch,
/// framework/cli/predict.cpp) and `skinlab-predict` (Eigen only, framework/predict_cli/), so
/// both take the same inputs and options, check the same things before any work and write the
/// same files:
///
///     <program> <input> [--rig rig.txt] [--model DIR] --out FILE [--out FILE ...]
///     <program> <input>... --out-dir DIR [--format glb|gltf|rig|h5]
///
/// The one-file form checks the input before the model is loaded, and every error is fatal. The
/// batch form loads the model once; an input is a character file, a directory (its character
/// files, geometry::is_character_file, sorted by name) or `@list.txt` (one path per line,
/// relative to the list file). Each character writes `DIR/<stem>.<ext>` (`<stem>_rig.txt` for
/// rig); two inputs with one output name, or an output that would replace an input, are an
/// error before any work. A character that fails is reported on one line and skipped; the
/// others are written, a summary table follows, and the exit status is 1 when any failed.
/// Outputs are written whole (atomic rename), so a failure never leaves a partial file.
///
/// What differs between the programs is the forward pass (a PredictEngine) and what
/// `skinlab predict` adds around it (comparison with the input's weights and rendering, through
/// PredictHooks).

#include <CLI/CLI.hpp>

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "framework/geometry/load_character.hpp"
#include "framework/infer/engine.hpp"
#include "framework/infer/prediction.hpp"

namespace skinlab::infer {

struct PredictArgs {
  std::vector<std::string> inputs;
  std::string rig;
  std::string model;
  std::string checkpoint = "best";
  std::vector<std::string> out;
  std::string out_dir;
  std::string format = "glb";
  double prune = 0.25;
  int max_vertices = 50000;
  std::string up = "y";
  bool compare = false;    ///< skinlab predict --compare-to-input
  bool timings = false;
  std::string render;      ///< skinlab predict --render
  std::string binder;      ///< skinlab predict --binder (infer/binder_engine.hpp)
  bool error_map = false;  ///< skinlab predict --error-map
};

/// What a program adds to the shared command.
struct PredictHooks {
  /// Loads the model in `dir` (--model, or the bundled one).
  std::function<std::unique_ptr<PredictEngine>(const std::filesystem::path& dir,
                                               const PredictArgs& args)>
      load;
  /// Called after each prediction, before its files are written (may be empty).
  std::function<void(const geometry::Character& input, const Prediction& p,
                     const PredictEngine& engine, const PredictArgs& args)>
      before_write;
  /// Called after the files of a one-input run are written (may be empty).
  std::function<void(const Prediction& p, const PredictArgs& args)> after_write;
};

/// Adds the inputs and the options both programs take to `cmd`: inputs, --rig, --model, --out,
/// --out-dir, --format, --prune, --up, --max-vertices, --timings.
void add_predict_options(CLI::App& cmd, PredictArgs& args);

/// Runs the command (one input or --out-dir); returns the exit status, throws Error for a
/// failure (the program prints it).
int run_predict(const PredictArgs& args, const PredictHooks& hooks);

/// +Y or +Z for "y" or "z"; Error otherwise.
Eigen::Vector3d up_axis(const std::string& up);

}  // namespace skinlab::infer

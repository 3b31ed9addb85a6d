#pragma once
/// \file
/// The torch-free parts of a model directory, shared by `skinlab predict` and `skinlab-predict`:
///
///   - a run directory of `skinlab train` (config.yaml, best.pt / last.pt): its preprocessing is
///     the `preparation` attribute of the run's dataset file (`data.file`,
///     data/dataset_file.hpp), which must still exist;
///   - a bundled model (`skinlab bundle`, results/bundled/<name>/): config.yaml, model.pt
///     (libtorch), parameters.h5 (the same parameters in a plain format, infer/parameters.hpp)
///     and preparation.yaml, self-contained.
///
/// The preparation YAML is "preprocess: {...}\ndistances: [...]" (the dataset's resolved
/// config), from which a model reads its one distance (HeterSkinNet Sec. 4.1–4.2).

#include <filesystem>
#include <string>

#include "framework/infer/prediction.hpp"

namespace skinlab::infer {

/// The model `predict`, `score` and `skinlab-predict` use without `--model`, the first that
/// exists of:
///   1. the directory in the environment variable SKINLAB_MODEL (an error when it is set but
///      holds no model);
///   2. the bundled model installed with the program: installed_data_dir() /
///      models/heterskinnet (`<prefix>/share/skinlab/models/heterskinnet`, cmake --install);
///   3. for a program of the build tree only (running_from_build_tree), the source tree's
///      results/bundled/heterskinnet.
/// None: an Error naming every place looked at. Logs (info) which one was taken.
std::filesystem::path default_model();

/// `dir`/config.yaml, the file every model directory has. IoError "<dir>: not a model directory
/// (no config.yaml); <hint>" when `dir` is not a directory or has none.
std::filesystem::path model_config_file(const std::filesystem::path& dir, const std::string& hint);

/// `dir`'s preparation YAML: `<dir>/preparation.yaml`, or else the `preparation` attribute of
/// the dataset file `data_file` (a run's `data.file`; empty: none). IoError naming the file
/// that is missing.
std::string read_preparation(const std::filesystem::path& dir, const std::string& data_file);

/// The preprocessing options of `yaml` (read_preparation's; `file` names it in errors) and
/// the distance plug-in `distance` it lists. ConfigError naming `dir` when it does not list it.
/// Of its priors (preprocess.priors) only `prior`, the one the model reads, is kept (empty:
/// none, so predicting never runs a binder the model ignores); ConfigError when it is missing.
Preparation parse_preparation(const std::string& yaml, const std::filesystem::path& file,
                              const std::filesystem::path& dir, const std::string& distance,
                              const std::string& prior = "");

/// parse_preparation(read_preparation(dir, data_file), ...): the preparation a model directory
/// predicts with, given its config's `data.file` and `data.distance` and the prior its model
/// reads (empty: none).
Preparation load_preparation(const std::filesystem::path& dir, const std::string& data_file,
                             const std::string& distance, const std::string& prior = "");

}  // namespace skinlab::infer

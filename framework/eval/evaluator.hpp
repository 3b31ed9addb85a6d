#pragma once
/// \file
/// Evaluation of a run (`skinlab eval`): the model of the run's config with the parameters of
/// one checkpoint, run on every character of one part of the configured split in eval mode
/// without gradients; its #V×K output scattered to #V×#B bone weights
/// (data::scatter_to_bones) and compared with the full ground-truth bone weights by every metric
/// of the config's `metrics:` list (metric.hpp), plus the training loss. A run whose config has
/// a `binder:` instead of a `model:` (binders/binder.hpp: GeoVoxel, bone heat) gets its #V×#B
/// weights from the binder, on the same characters and with the same metrics, and has no
/// checkpoint and no loss. Three binder types are rows the evaluator computes from the dataset
/// file (binders::is_reference_row): the artist's weights and the training targets scored as a
/// prediction (the ceilings of every metric), and a stored prior on the candidates. Per-character values
/// are averaged over the characters (each character counts once, the RigNet-lineage
/// convention).
///
/// Files written into the run directory (each atomically):
///
///     eval_<part>.json                 {"mean": {...}, "per_character": [...], checkpoint, epoch, ...}
///     eval_<part>.csv                  one row per character: character, vertices, bones, values
///     predictions/<part>.h5            predictions.hpp (at the source vertices and prepared ones)
///     predictions/<part>/<name>_rig.txt  RigNet rig text at the source vertices, source frame

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "framework/core/run_dir.hpp"

namespace skinlab::train {
class World;
}  // namespace skinlab::train

namespace skinlab::eval {

struct EvalOptions {
  std::string part = "test";          ///< train, val or test of the configured split
  std::string checkpoint = "best";    ///< best or last
  bool predictions = true;            ///< write predictions/ (rig text and HDF5)
  /// Applied to the run's config.yaml, e.g. `data.file=...` when the dataset has moved.
  std::vector<std::string> overrides;
  /// Sharded evaluation (`skinlab eval --nproc N`, train/distributed.hpp): process r evaluates
  /// every N-th character of the part from the r-th; rank 0 gathers their values and
  /// predictions and writes every file, the others return an empty report. nullptr: alone.
  train::World* world = nullptr;
};

struct CharacterResult {
  std::string name;
  int vertices = 0;
  int bones = 0;
  std::map<std::string, double> values;  ///< "loss" and every metric's values
};

struct EvalReport {
  std::string split, part, checkpoint;
  int epoch = 0;                          ///< epoch of the checkpoint
  std::map<std::string, double> mean;     ///< over characters
  std::vector<CharacterResult> characters;
  std::filesystem::path json, csv, predictions;  ///< files written (predictions: "" if off)
  double seconds = 0;
};

/// The mean of each named value over the characters (eval::mean_over_characters: every character
/// reports the same names, the loss and the configured metrics; NaN stays NaN).
std::map<std::string, double> mean_values(const std::vector<CharacterResult>& characters);

/// Writes `report` into `run` as eval_<part>.json (the fields of `header`, then characters,
/// mean, per_character and seconds) and eval_<part>.csv (one row per character), each
/// atomically, and sets report.json and report.csv. Every task's evaluation writes through it,
/// so `skinlab table` reads them alike.
void write_eval_files(const RunDir& run, EvalReport& report, nlohmann::json header);

/// Evaluates `run` (see the file comment; EvalOptions::world for several processes). Throws Error/IoError/ConfigError for: an unknown part
/// or checkpoint name, a missing checkpoint, a checkpoint that does not match the model of the
/// config, a missing dataset or split, an empty part.
EvalReport evaluate(const RunDir& run, const EvalOptions& options);

}  // namespace skinlab::eval

#pragma once
/// \file
/// `skinlab prepare`: builders → preprocessing (preprocess.hpp) → one dataset file
/// (dataset_file.hpp), in parallel over characters, resumable and safe to kill at any time.
///
/// Config (configs/datasets/<name>.yaml):
///
///     sources:            # dataset registry nodes, read in order
///       - {type: folder, path: ..., licence: ..., attribution: ..., skeleton: ...}
///     cleaning: {...}     # CleaningOptions (clean.hpp; all optional)
///     preprocess: {...}   # PreprocessOptions (all optional)
///     distances:          # distance registry nodes; each type at most once
///       - {type: hollow_dist, resolution: 88}
///     splits: {...}       # SplitOptions (splits.hpp; all optional)
///     output: results/datasets/name.h5
///
/// Order: builders → cleaning (drops and variant groups) → preprocessing of each kept
/// character → splits over the characters that preprocessed successfully → augmented copies
/// (`preprocess.augment`, augment.hpp) → one file.
///
/// Augmented copies are for training only. With `preprocess.augment.copies: N`, every character
/// that the train part of at least one split holds gets N copies ("<name>~aug<i>", attribute
/// `augmented_from`), preprocessed like any character after their deformation. They come after
/// every original in the file, so the originals' indices and splits are those of the same
/// config without augmentation; a copy joins the train part of every split whose train part
/// holds its original and never a val or test part, and a character some split tests or
/// validates on has no copy in the train part of that split (splits never divide a variant
/// group, so no geometry of a test group reaches training). A copy that fails is excluded with
/// its reason, as a character is.
///
/// Resumability. Each character is preprocessed into `<output>.partial/<name>.h5` (a dataset file
/// holding that one character), written through a temporary file and renamed into place, so a
/// file under its final name is complete. A later run reuses such a file when it reads and
/// validates and was made with the same `preprocess:` and `distances:` config (the `preparation`
/// attribute); otherwise the character is recomputed. When every character is done, the
/// per-character files are merged into `output` (again through a temporary file) and the partial
/// directory is removed (unless keep_partial). Killing the process at any point therefore loses
/// at most the characters in flight.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "framework/data/source.hpp"
#include "framework/core/config.hpp"
#include "framework/data/clean.hpp"
#include "framework/data/preprocess.hpp"
#include "framework/data/splits.hpp"

namespace skinlab::data {

struct PrepareConfig {
  std::vector<config::Node> sources;  ///< dataset registry nodes
  CleaningOptions cleaning;
  PreprocessOptions preprocess;
  SplitOptions splits;
  std::vector<config::Node> distances;  ///< distance registry nodes
  std::filesystem::path output;
  /// The resolved `preprocess:` and `distances:` sections as YAML (Dataset::preparation).
  std::string preparation;

  /// Decodes and validates the whole config, including every source and distance node (their
  /// plug-ins are constructed once here), before any work starts.
  static PrepareConfig from(const config::Config& config);
};

struct PrepareOptions {
  int threads = 0;            ///< characters (and the TBB work inside them); 0: every core
  bool keep_partial = false;  ///< keep `<output>.partial/` after the merge
  bool progress = true;       ///< report progress on stderr (framework/core/progress.hpp)
  /// Sharded preparation (`skinlab prepare --nproc N`): with shard_count > 1 this process only
  /// preprocesses the characters i with i mod shard_count = shard_index (in the cleaned order,
  /// which every process computes alike) into `<output>.partial/`, and writes no output file.
  /// With augmentation it also makes the copies of its characters that train in the splits
  /// over every cleaned character (the merge computes the final splits and any copy missing).
  /// A run with shard_count 1 afterwards merges them: every partial file is reused, and only
  /// what no shard finished (a character that failed is tried again) is computed.
  int shard_index = 0;
  int shard_count = 1;
};

struct PrepareReport {
  std::filesystem::path output;
  std::size_t characters = 0;                ///< characters in the output file
  std::size_t copies = 0;                    ///< of them, augmented copies (augment.hpp)
  std::size_t computed = 0;                  ///< preprocessed in this run
  std::size_t reused = 0;                    ///< taken from an existing partial file
  std::vector<datasets::Excluded> excluded;  ///< by builders and by preprocessing
  double seconds = 0;
};

/// Runs the pipeline of the file comment. A character that fails preprocessing is excluded with
/// its reason (not fatal); a source that cannot be read at all, or a failure to write, throws.
PrepareReport prepare_dataset(const PrepareConfig& config, const PrepareOptions& options = {});

}  // namespace skinlab::data

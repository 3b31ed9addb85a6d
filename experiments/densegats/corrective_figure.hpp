#pragma once
/// \file
/// Error-colour figures of evaluated corrective runs (DenseGATs, Li et al. I3D 2020, Fig. 8-10):
/// for a test character at a few of its evaluation poses, the ground truth (the Delta Mush
/// target, corrective_data.hpp) in grey, then one column per run with the run's deformed mesh
/// (LBS + its correction; LBS itself for the `lbs` row, DQS for `dqs`) coloured by each vertex's
/// distance to the target in cm at the task's height, front view above side view, with one
/// colour scale per figure. Fig. 10 is the columns ground truth, LBS, DQS, DenseGATs; Fig. 11
/// the networks of Table 3 side by side.
///
/// Reads each run's `predictions/<part>.h5` that `skinlab eval` writes for a corrective run:
///
///     /characters/<name>/poses          P int32 pose indices into the character's pose list
///     /characters/<name>/correction_cm  (P·V)×3 float32 the method's displacement over LBS, cm
///     /characters/<name>/error_cm       P×V float32 |correction − target displacement|, cm
///     /character_names                  strings, in evaluation order
///     attributes on /: task (corrective), experiment, run, split, part, checkpoint, epoch, method
///
/// The LBS meshes and targets are rebuilt from the dataset and the `corrective:` options of the
/// first run's config; every run must have been evaluated at the same poses, and the rebuilt
/// targets must reproduce the saved errors (else the dataset changed since the evaluation), or
/// an IoError names the run, character and pose.

#include <filesystem>
#include <string>
#include <vector>

#include "framework/report/figure_options.hpp"

namespace skinlab::densegats {

/// Writes `<out>/<character>_pose<index>.png` per character and pose, one vertex-coloured PLY
/// per run, character and pose under `<out>/<experiment>/`, and `<out>/README.md` (captions,
/// per-run mean errors of each figure, the command). Throws IoError / ConfigError as the file
/// comment says; nothing is written before every run is opened and checked. Reads runs, part,
/// characters, count, poses, error_max_cm and out of `options`; `command` is quoted in the
/// README.
void write_corrective_figures(const report::FigureOptions& options, const std::string& command);

}  // namespace skinlab::densegats

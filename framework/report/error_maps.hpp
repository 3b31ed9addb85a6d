#pragma once
/// \file
/// Per-vertex error maps of evaluated skinning runs side by side (HeterSkinNet Fig. 7 and 10: the
/// L1 error of the weights, and the deformation error of Sec. 4.3 per vertex): one PNG per
/// character and map, one vertex-coloured PLY per run, character and map
/// (report/mesh_figure.hpp), and `<out>/README.md` with the captions and the command. Reads each
/// run's saved predictions (`predictions/<part>.h5`, written by `skinlab eval`), the dataset its
/// config names, and the run's own `metrics:` options (pruning, poses), so the maps average to
/// the run's eval numbers. What `skinlab figure` draws for skinning runs.

#include "framework/report/figure_options.hpp"

namespace skinlab::report {

/// Writes the maps of `options.runs` (reads part, characters, count, l1_max, out); prints a line per character to stdout. IoError for a run without saved
/// predictions of the part or a character missing from a run or its dataset.
void write_error_maps(const FigureOptions& options);

}  // namespace skinlab::report

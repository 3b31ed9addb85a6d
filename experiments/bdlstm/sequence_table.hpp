#pragma once
/// \file
/// Qiao et al.'s Tables 1-2 from evaluated sequence runs (`skinlab table` and `skinlab sweep`
/// use it when the runs are of `task: sequence`; sequence_task.hpp defines the values).
///
/// One row per method and number of initial frames (a network run gives "<experiment> (1 IF)"
/// and "(3 IF)"; ACAP extrapolation "(2 IF)"; the held frame "(1 IF)"), plus the representation's
/// floor (the true features decoded); one column per character and horizon, as the paper's
/// Table 1 has one per sequence and frame. Runs of the same experiment on different characters
/// fill the same row. A cell no run reports (a character whose held-out windows are too short
/// for the horizon, or a method not run on it) is "—". Under the table: how many predictions
/// each cell averages, the metric definition and the command.

#include <string>
#include <vector>

#include "framework/report/table.hpp"

namespace skinlab::bdlstm {

/// The table text, Markdown (`md`) or CSV (`csv`). Throws Error for no runs, another format,
/// a run that is not a sequence run, or a run without any e<h>_<u>if_mm value.
std::string sequence_table(const std::vector<report::RunResult>& runs,
                           const report::TableOptions& options);

}  // namespace skinlab::bdlstm

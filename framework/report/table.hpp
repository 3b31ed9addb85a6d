#pragma once
/// \file
/// Result tables generated from saved run directories, never typed (HeterSkinNet Table 3: every
/// method; Table 4: the ablations). `skinlab table <run_dir>... [--part test] [--format md|csv|tex]`
/// reads each run's `eval_<part>.json` (framework/eval/evaluator.hpp) and writes one row per run:
/// mean ± standard deviation over the part's characters of every metric, and a one-way ANOVA
/// (eval/anova.hpp) of the per-character values of the reference run (the first) against each
/// other run, per metric (Sec. 4.5, Fig. 9), and beside it a paired t-test on the same
/// characters (eval/paired_t.hpp: the two rows are not independent samples); with a single
/// character per run there are no tests (no degrees of freedom), only the rows. A run made or
/// resumed by a build from a modified source tree (its env.json) is marked † with a note.
///
/// Every run must have been evaluated on the same characters (same dataset, split and part);
/// otherwise the comparison would not mean anything, and it is an error naming the run and the
/// first character that differs. The standard deviation is the sample one (n − 1).

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace skinlab::report {

/// One evaluated run as the table sees it.
struct RunResult {
  std::filesystem::path dir;
  std::string label;       ///< the run's experiment name (e.g. heterskinnet_no_smoothing)
  std::string task = "skinning";  ///< the eval report's task (skinning, corrective, sequence)
  std::string run_id;
  std::string dataset, split, part;
  std::string checkpoint;  ///< best, last, or none (a binder)
  int epoch = 0;
  std::vector<std::string> characters;                ///< in evaluation order
  std::map<std::string, std::vector<double>> values;  ///< metric → per-character values
  std::string metrics_yaml;  ///< the run config's `metrics:` section (YAML), to state thresholds
  /// A task's own statement of what its values are (eval_<part>.json `metric_definitions`;
  /// the corrective task's errors have no `metrics:` section), stated under the table instead.
  std::string metric_definitions;
  /// The run's env.json says a build from a modified tree made or resumed it (`git_dirty`, or a
  /// resume's); tables mark it with †. False without an env.json.
  bool dirty = false;
  /// What an entry of `characters` is (plural, for the note under a table): "characters", or
  /// after average_over_units the unit, e.g. "skeleton families".
  std::string unit = "characters";
  /// The characters averaged into those units (0 when not averaged).
  std::size_t members = 0;
};

/// Reads `<dir>/eval_<part>.json`, the `metrics` section of `<dir>/config.yaml` and the git state
/// of `<dir>/env.json` (each of the last two if present). Throws
/// IoError naming the file when it is missing (with the `skinlab eval` command that writes it)
/// or malformed.
RunResult load_run_result(const std::filesystem::path& dir, const std::string& part);

struct TableOptions {
  /// Metric columns, in order; default: precision, recall, avg_l1, deformation_error.
  std::vector<std::string> metrics = {"precision", "recall", "avg_l1", "deformation_error"};
  std::string format = "md";  ///< md, csv or tex
  std::string title;          ///< a caption line (md: a heading; tex: \caption)
  std::string command;        ///< the command that generated the table, quoted under it
  /// Runs of one experiment (seeds) form one row: mean ± sample standard deviation across the
  /// runs of their means over characters; the ANOVA compares each character's mean over the
  /// runs. Without it every run is a row of its own.
  bool group_runs = false;
  /// The generalisation table (make_split_table) instead of one test part.
  bool across_splits = false;
};

/// Counts the runs evaluated on dataset file `from` as evaluated on `to` (`skinlab table
/// --same-data FROM=TO`): for a dataset prepared again with additions only (e.g. priors,
/// configs/datasets/games_all_prior.yaml on games_all.yaml), whose test parts are the same
/// characters, so its runs share the columns of the other file's runs; the table still checks
/// the characters. Throws Error when no run was evaluated on `from`.
void count_as_same_data(std::vector<RunResult>& runs, const std::string& from, const std::string& to);

/// Makes a run's entries units of several characters (`skinlab table --per family|group`):
/// each unit's value of a metric is the mean over its characters where the metric is defined
/// (NaN when it is nowhere), units in order of their first character. The tests then count
/// units, not characters: 0 A.D.'s 34 human garment variants share one skeleton and one artist's
/// conventions, so as 34 characters they would weigh as 34 independent samples. `unit_of` maps
/// a character to its unit (data::read_character_units), `unit` names the units in the plural.
/// Throws Error naming the run and the character when a character has no unit.
void average_over_units(RunResult& run, const std::map<std::string, std::string>& unit_of,
                        const std::string& unit);

/// The table text (see the file comment). Throws Error for fewer than one run, an unknown
/// format, a metric missing from a run (naming both), or runs on different characters.
std::string make_table(const std::vector<RunResult>& runs, const TableOptions& options);

/// The generalisation table: rows are methods (run labels, in order of appearance), columns are
/// the test sets the runs were evaluated on (one per dataset and split, e.g. the
/// leave-one-source-out splits, in order of appearance) and, with more than one, their union
/// (every character of every column, for a method evaluated on all of them). One such table per
/// metric; a cell is the mean over its characters and, below the first row, the p of a one-way
/// ANOVA and of a paired t-test over characters against the first row's method on the same
/// characters. A cell with
/// several runs of one method needs `group_runs` (then each character's mean over the runs).
/// make_table dispatches here when `options.across_splits` is set. Throws Error as make_table,
/// and when a cell's runs, or a column's methods, were evaluated on different characters.
std::string make_split_table(const std::vector<RunResult>& runs, const TableOptions& options);

}  // namespace skinlab::report

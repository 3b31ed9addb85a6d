/// \file
/// `skinlab table <run_dir>... [--part test] [--format md|csv|tex] [--metrics a,b] [--title T]
/// [--out file] [--group-runs] [--across-splits] [--same-data FROM=TO]... [--per character|family|group]`: the comparison table of saved, evaluated runs
/// (framework/report/table.hpp); the first run is the reference of the ANOVA columns. Without
/// --out it prints the table.

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <utility>

#include "framework/cli/commands.hpp"
#include "framework/task/task.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/error.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/report/table.hpp"

namespace skinlab::cli {

namespace {

/// `--per family|group`: every run's characters averaged into the units of its dataset file, or
/// of a file that --same-data counts as the same data (`same`: FROM, TO pairs) when that one is
/// not on this machine; one read per dataset.
void average_per_unit(std::vector<report::RunResult>& runs, const std::string& per,
                      const std::vector<std::pair<std::string, std::string>>& same) {
  std::map<std::string, std::map<std::string, std::string>> units_of_dataset;
  for (auto& run : runs) {
    auto units = units_of_dataset.find(run.dataset);
    if (units == units_of_dataset.end()) {
      std::vector<std::string> files{run.dataset};
      for (const auto& [from, to] : same) {
        if (to == run.dataset) files.push_back(from);
      }
      const auto file = std::find_if(files.begin(), files.end(), [](const std::string& f) {
        return std::filesystem::exists(f);
      });
      if (file == files.end()) {
        throw IoError(run.dataset + ": not found; `--per " + per + "` reads the units from the " +
                      "dataset file " + run.dir.string() + " was evaluated on (prepare it with " +
                      "skinlab prepare, or leave out --per)");
      }
      units = units_of_dataset.emplace(run.dataset, data::read_character_units(*file, per)).first;
    }
    report::average_over_units(run, units->second,
                               per == "family" ? "skeleton families" : "variant groups");
  }
}

}  // namespace

Command add_table(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "table", "Table 3/4 from evaluated run directories: mean ± sd per metric, one-way ANOVA "
               "of the first run against each other run");
  struct Args {
    std::vector<std::string> runs;
    std::string part = "test";
    std::string out;
    report::TableOptions options;
    std::vector<std::string> same_data;
    std::string per = "character";
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("runs", args->runs, "run directories; the first is the reference")->required();
  cmd->add_option("--part", args->part, "evaluated part (eval_<part>.json)")->capture_default_str();
  cmd->add_option("--format", args->options.format, "md, csv or tex")->capture_default_str();
  cmd->add_option("--metrics", args->options.metrics, "metric columns, in order")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--title", args->options.title, "caption");
  cmd->add_option("--out", args->out, "file to write (atomically); default: standard output");
  cmd->add_flag("--group-runs", args->options.group_runs,
                "runs of one experiment (seeds) form one row: mean ± sd across the runs");
  cmd->add_flag("--across-splits", args->options.across_splits,
                "generalisation table: methods x the test sets the runs were evaluated on");
  cmd->add_option("--same-data", args->same_data,
                  "FROM=TO: runs evaluated on dataset file FROM count as evaluated on TO (e.g. a "
                  "dataset prepared again with priors added: the same characters and splits); "
                  "the table still requires the same test characters");
  cmd->add_option("--per", args->per,
                  "the statistics' unit: character, family (skeleton family: the mean over its "
                  "characters) or group (variant group); family and group read the dataset file "
                  "each run was evaluated on")
      ->check(CLI::IsMember({"character", "family", "group"}))
      ->capture_default_str();
  return {cmd, [args] {
            std::vector<report::RunResult> runs;
            for (const auto& dir : args->runs) runs.push_back(report::load_run_result(dir, args->part));
            std::vector<std::pair<std::string, std::string>> same;
            for (const auto& pair : args->same_data) {
              const auto eq = pair.find('=');
              if (eq == std::string::npos || eq == 0 || eq + 1 == pair.size()) {
                throw ConfigError("table: --same-data '" + pair + "' is not FROM=TO");
              }
              same.emplace_back(pair.substr(0, eq), pair.substr(eq + 1));
              report::count_as_same_data(runs, same.back().first, same.back().second);
            }
            if (args->per != "character") average_per_unit(runs, args->per, same);
            std::string command;
            for (std::size_t i = 1; i < command_line().size(); ++i) {
              const std::string& word = command_line()[i];
              const bool plain = word.find_first_of(" \t'\"$`\\*?;&|()<>") == std::string::npos;
              command += plain ? " " + word : " '" + word + "'";
            }
            command = "skinlab" + command;
            args->options.command = command;
            const std::string text = task::table_text(runs, args->options);
            if (args->out.empty()) {
              std::cout << text;
            } else {
              const std::filesystem::path out = args->out;
              if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
              write_file_atomic(out, text);
              std::cout << "wrote " << args->out << " (" << runs.size() << " runs)\n";
            }
            return 0;
          }};
}

}  // namespace skinlab::cli

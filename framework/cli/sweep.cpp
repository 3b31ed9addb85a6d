/// \file
/// `skinlab sweep <sweep.yaml> [--threads N]`: trains (or, for binders, runs) and evaluates
/// every entry of a sweep, then writes their table (framework/report/table.hpp). This is how
/// Table 3 (`configs/sweeps/table3.yaml`) and Table 4 (`configs/sweeps/table4.yaml`) are made.
///
///     name: table4                      # every entry's run id: <results_dir>/<experiment>/<name>
///     title: "Table 4: ablations"       # the table's caption
///     part: test                        # evaluated part (default test)
///     overrides: [data.file=...]        # applied to every entry, before its own
///     predictions: false                # write predictions/ for every run (default false)
///     metrics: [precision, recall, avg_l1, deformation_error]  # table columns
///     group_runs: true                  # runs of one experiment (seeds) form one row (default false)
///     out: results/tables/table4.md     # the table (Markdown); table4.csv is written beside it
///     runs:                             # the first is the reference of the ANOVA columns
///       - configs/heterskinnet.yaml
///       - {config: configs/ablations/euclidean.yaml, overrides: [seed=1], run_id: table4-seed1}
///       - {run: results/heterskinnet/full-20261123}   # an existing run: evaluated if needed
///     each:                             # optional: every `config:` entry once per value
///       override: "sequences.characters=[{}]"   # {} is the value; after the sweep's overrides
///       values: [wolf, mastiff]
///
/// An entry's run id is the sweep's name unless it sets `run_id`; with `each`, "-<value>" is
/// appended (table4-seed1-wolf). This is how one network per character (the mesh-sequence task,
/// Qiao et al. Sec. 3.2) or one run per seed is swept from one file. Two entries that would
/// share a run directory (same experiment and run id) are an error.
///
/// A sweep can be interrupted and run again: an entry whose run directory exists continues
/// (training resumes from last.pt and the run is evaluated after it; a finished run that trains
/// no further epoch keeps its saved evaluation and is only evaluated if that is missing),
/// provided the resolved config is unchanged; a changed config is an error naming the run, so
/// results are never mixed. Like `skinlab train` and `skinlab eval`, a sweep holds
/// an entry's `train.lock` while training it and `eval_<part>.lock` while evaluating it
/// (core/output_lock.hpp), so a sweep and another process never write the same run at once.
///
/// `--table-only` trains and evaluates nothing: the table is written from the entries already
/// evaluated (`eval_<part>.json` in their run directories, with the config the entry resolves
/// to now), and the others are named under it as not yet run. This is how a sweep's table is
/// brought up to date while some of its runs are still training elsewhere or not started.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <iostream>
#include <map>

#include "framework/tensors/threads.hpp"
#include "framework/cli/commands.hpp"
#include "framework/task/task.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/output_lock.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/eval/evaluator.hpp"
#include "framework/report/table.hpp"
#include "framework/train/run_options.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::cli {

namespace {

namespace fs = std::filesystem;

struct Entry {
  std::string run;     ///< an existing run directory (then `config` is empty)
  std::string config;
  std::vector<std::string> overrides;
  std::string run_id;  ///< empty: the sweep's name
};

struct Sweep {
  std::string name, title, part = "test", out;
  std::vector<std::string> overrides;
  std::vector<std::string> metrics = report::TableOptions{}.metrics;
  bool predictions = false;
  bool group_runs = false;  ///< report::TableOptions::group_runs
  std::vector<Entry> runs;  ///< after `each` is expanded

  /// `each`: every `config:` entry once per value, `override` with {} replaced by the value.
  static std::vector<Entry> expand(const std::string& name, std::vector<Entry> entries,
                                   const config::Node& each) {
    std::string override_pattern;
    std::vector<std::string> values;
    config::Fields e(each, "the sweep's `each`", {});
    e.required("override", override_pattern)
        .check(override_pattern.find("{}") != std::string::npos, "override",
               "must contain {} (where each value goes)");
    e.required("values", values).check(!values.empty(), "values", "must not be empty");
    for (const std::string& v : values) {
      e.check(!v.empty() && v.find_first_of("/\\ \t") == std::string::npos, "values",
              "'" + v + "' cannot be part of a run directory's name");
    }
    e.finish();
    std::vector<Entry> out;
    for (const Entry& entry : entries) {
      if (!entry.run.empty()) {
        each.fail("applies to `config:` entries; '" + entry.run + "' is an existing run");
      }
      for (const std::string& v : values) {
        Entry x = entry;
        std::string o = override_pattern;
        o.replace(o.find("{}"), 2, v);
        x.overrides.insert(x.overrides.begin(), o);
        x.run_id = (entry.run_id.empty() ? name : entry.run_id) + "-" + v;
        out.push_back(std::move(x));
      }
    }
    return out;
  }

  static Sweep from(const config::Config& file) {
    Sweep s;
    config::Fields f(file.root(), "the sweep", {});
    f.required("name", s.name).check(!s.name.empty(), "name", "must not be empty");
    f.optional("title", s.title);
    f.optional("part", s.part);
    f.required("out", s.out);
    f.optional("overrides", s.overrides);
    f.optional("metrics", s.metrics);
    f.optional("predictions", s.predictions);
    f.optional("group_runs", s.group_runs);
    const config::Node runs = f.section("runs");
    const config::Node each = f.section("each");
    f.finish();
    if (!runs.is_sequence() || runs.size() == 0) runs.fail("expected a non-empty list of runs");
    for (std::size_t i = 0; i < runs.size(); ++i) {
      Entry e;
      if (runs[i].is_scalar()) {
        e.config = runs[i].as<std::string>();
      } else {
        config::Fields r(runs[i], "a sweep entry", {});
        r.optional("run", e.run);
        r.optional("config", e.config);
        r.optional("overrides", e.overrides);
        r.optional("run_id", e.run_id);
        r.check(e.run.empty() != e.config.empty(), "config",
                "give either `config:` (a run to make) or `run:` (an existing run directory)");
        r.check(e.run.empty() || (e.overrides.empty() && e.run_id.empty()), "run",
                "an existing run takes no overrides or run_id");
        r.finish();
      }
      s.runs.push_back(std::move(e));
    }
    if (each.exists()) s.runs = expand(s.name, std::move(s.runs), each);
    return s;
  }
};

/// An entry's config with the sweep's overrides and then its own.
config::Config entry_config(const Sweep& sweep, const Entry& entry) {
  std::vector<std::string> overrides = sweep.overrides;
  overrides.insert(overrides.end(), entry.overrides.begin(), entry.overrides.end());
  return config::Config::load(entry.config, overrides);
}

/// A `config:` entry's run id: its own, else the sweep's name.
std::string run_id_of(const Sweep& sweep, const Entry& entry) {
  return entry.run_id.empty() ? sweep.name : entry.run_id;
}

/// The run directory of a `config:` entry whose resolved config gave `o`:
/// <results_dir>/<experiment>/<run id>.
fs::path run_dir_of(const train::RunOptions& o, const Sweep& sweep, const Entry& entry) {
  return fs::path(o.results_dir) / o.experiment / run_id_of(sweep, entry);
}

/// Error unless the run directory `dir`, if it exists, was made with `config` (so a sweep never
/// mixes the results of another config into its table).
void require_same_config(const fs::path& dir, const config::Config& config, const Entry& entry) {
  if (!fs::exists(dir)) return;
  if (read_file(dir / "config.yaml") != config.to_yaml()) {
    throw Error(dir.string() + ": exists with another config than " + entry.config +
                " resolves to now; move it away or rename the sweep");
  }
}

/// Trains or opens the run of one entry and evaluates it; returns its run directory.
fs::path run_entry(const Sweep& sweep, const Entry& entry, int threads) {
  if (!entry.run.empty()) {
    const RunDir run = RunDir::open(entry.run);
    std::cout << fmt::format("== {} (existing run)\n", entry.run);
    if (!fs::exists(run.file("eval_" + sweep.part + ".json"))) {
      eval::EvalOptions e;
      e.part = sweep.part;
      e.predictions = sweep.predictions;
      if (threads >= 0) set_torch_threads(threads);
      const OutputLock lock(eval_lock_of(run.path(), e.part),
                            run.file("eval_" + e.part + ".json").string(), command_line());
      task::evaluate_run(run, e);
    }
    return run.path();
  }
  const config::Config config = entry_config(sweep, entry);
  const train::RunOptions o = train::RunOptions::from(config);
  const bool binder = task::get(o.task).untrained(config, o);
  if (!binder) o.require_training_sections(config);
  set_torch_threads(threads >= 0 ? threads : o.threads);

  const fs::path dir = run_dir_of(o, sweep, entry);
  const bool existed = fs::exists(dir);
  require_same_config(dir, config, entry);
  // An untrained method (binder, baseline) whose run has its evaluation is not evaluated again:
  // the same config gives the same values, and its dataset need not be on this machine.
  if (existed && binder && fs::exists(dir / ("eval_" + sweep.part + ".json"))) {
    std::cout << fmt::format("== {} → {} (saved evaluation)\n", entry.config, dir.string());
    return dir;
  }
  // A committed run keeps its evaluation but not its checkpoints (git ignores *.pt): its saved
  // evaluation is its row. Without both it can neither resume nor be evaluated, and training
  // it again from scratch would overwrite its history, so that is an error.
  if (existed && !binder && !fs::exists(dir / train::kLastCheckpoint)) {
    if (fs::exists(dir / ("eval_" + sweep.part + ".json"))) {
      std::cout << fmt::format("== {} → {} (saved evaluation; no checkpoint to resume)\n",
                               entry.config, dir.string());
      return dir;
    }
    if (fs::exists(dir / "metrics.jsonl") && fs::file_size(dir / "metrics.jsonl") > 0) {
      throw Error(fmt::format("{}: has trained epochs (metrics.jsonl) but neither {} nor "
                              "eval_{}.json; move it away to train it again",
                              dir.string(), train::kLastCheckpoint, sweep.part));
    }
  }
  std::cout << fmt::format("== {} ({}) → {}\n", entry.config, binder ? "evaluate only" : "train",
                           dir.string());
  // The trainer is made (its config checked) before a new run directory is.
  const std::unique_ptr<task::TaskTrainer> trainer = binder ? nullptr : task::make_trainer(config);
  const RunDir run = existed ? RunDir::open(dir)
                             : train::create_run(config, o, run_id_of(sweep, entry), command_line());
  if (trainer) {
    train::TrainResult r;
    {
      const OutputLock lock(train_lock_of(run.path()), run.path().string(), command_line());
      r = trainer->fit(run, {});
    }
    spdlog::info("{}: {} epochs, best epoch {} (validation loss {:.6g})", o.experiment, r.epochs,
                 r.best_epoch, r.best_loss);
    // A finished run that trained nothing now keeps its evaluation: evaluating the same
    // checkpoint again would only rewrite eval_<part>.* and env.json with values that differ in
    // the last digits (another thread count), which is noise in a committed run.
    if (existed && r.epochs_this_call == 0 &&
        fs::exists(run.file("eval_" + sweep.part + ".json"))) {
      std::cout << fmt::format("   finished after {} epochs; saved evaluation kept\n", r.epochs);
      return run.path();
    }
  }
  eval::EvalOptions e;
  e.part = sweep.part;
  e.predictions = sweep.predictions;
  const OutputLock lock(eval_lock_of(run.path(), e.part),
                        run.file("eval_" + e.part + ".json").string(), command_line());
  const eval::EvalReport report = task::evaluate_run(run, e);
  std::cout << fmt::format("   {} characters, {:.1f} s\n", report.characters.size(), report.seconds);
  return run.path();
}

}  // namespace

Command add_sweep(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "sweep", "train/run and evaluate every entry of a sweep file, then write their table");
  struct Args {
    std::string file;
    int threads = -1;
    bool table_only = false;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("file", args->file, "sweep file (YAML), e.g. configs/sweeps/table4.yaml")
      ->required();
  cmd->add_option("--threads", args->threads,
                  "libtorch threads for every entry (default: each config's `threads`)");
  cmd->add_flag("--table-only", args->table_only,
                "train and evaluate nothing: the table of the entries already evaluated, the "
                "others named under it as not yet run");
  return {cmd, [args] {
            const Sweep sweep = Sweep::from(config::Config::load(args->file));
            // Every entry's config must load before anything trains, and no two entries may
            // share a run directory.
            std::map<fs::path, std::string> dirs;
            for (const auto& entry : sweep.runs) {
              if (!entry.run.empty()) {
                RunDir::open(entry.run);  // must exist
                continue;
              }
              const fs::path dir =
                  run_dir_of(train::RunOptions::from(entry_config(sweep, entry)), sweep, entry);
              if (!dirs.emplace(dir, entry.config).second) {
                throw Error(args->file + ": " + entry.config + " and " + dirs[dir] +
                            " would share the run directory " + dir.string() +
                            "; give one of them a run_id");
              }
            }
            std::vector<report::RunResult> results;
            std::vector<std::string> not_run;  // --table-only: entries without an evaluation
            for (const auto& entry : sweep.runs) {
              if (!args->table_only) {
                results.push_back(report::load_run_result(run_entry(sweep, entry, args->threads),
                                                          sweep.part));
                continue;
              }
              fs::path dir = entry.run;
              if (entry.run.empty()) {
                const config::Config config = entry_config(sweep, entry);
                dir = run_dir_of(train::RunOptions::from(config), sweep, entry);
                require_same_config(dir, config, entry);
              }
              if (fs::exists(dir / ("eval_" + sweep.part + ".json"))) {
                results.push_back(report::load_run_result(dir, sweep.part));
              } else {
                not_run.push_back(dir.string());
              }
            }
            if (results.empty()) {
              throw Error(args->file + ": no entry has been evaluated on the " + sweep.part +
                          " part yet (eval_" + sweep.part + ".json); run the sweep without "
                          "--table-only");
            }
            report::TableOptions t;
            t.metrics = sweep.metrics;
            t.title = sweep.title;
            t.group_runs = sweep.group_runs;
            t.command = "skinlab sweep " + args->file + (args->table_only ? " --table-only" : "");
            std::string md = task::table_text(results, t);
            if (!not_run.empty()) {
              md += fmt::format("\nNot yet run or evaluated (`skinlab sweep {}` runs them): `{}`.\n",
                                args->file, fmt::join(not_run, "`, `"));
            }
            t.format = "csv";
            const fs::path out = sweep.out;
            if (out.has_parent_path()) fs::create_directories(out.parent_path());
            write_file_atomic(out, md);
            write_file_atomic(fs::path(out).replace_extension(".csv"), task::table_text(results, t));
            std::cout << md << "wrote " << out.string() << "\n";
            return 0;
          }};
}

}  // namespace skinlab::cli

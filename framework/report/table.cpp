#include "framework/report/table.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <nlohmann/json.hpp>

#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/eval/anova.hpp"
#include "framework/eval/paired_t.hpp"
#include "framework/eval/value_display.hpp"

namespace skinlab::report {

namespace fs = std::filesystem;

namespace {

struct MeanSd {
  double mean = 0, sd = 0;
};

/// The values of `all` that are not NaN (a metric undefined for a character, evaluate.hpp).
std::vector<double> defined(const std::vector<double>& all) {
  std::vector<double> x;
  for (double v : all) {
    if (!std::isnan(v)) x.push_back(v);
  }
  return x;
}

MeanSd stats_of(const std::vector<double>& all) {
  const std::vector<double> x = defined(all);
  MeanSd s;
  if (x.empty()) return {std::nan(""), std::nan("")};
  for (double v : x) s.mean += v;
  s.mean /= static_cast<double>(x.size());
  if (x.size() > 1) {
    for (double v : x) s.sd += (v - s.mean) * (v - s.mean);
    s.sd = std::sqrt(s.sd / static_cast<double>(x.size() - 1));
  }
  return s;
}

std::string value_text(double v, const eval::ValueDisplay& c) {
  return c.percent ? fmt::format("{:.{}f}%", 100 * v, c.decimals) : fmt::format("{:.{}f}", v, c.decimals);
}

std::string p_text(double p) {
  if (std::isnan(p)) return "nan";
  return p < 1e-4 ? fmt::format("{:.1e}", p) : fmt::format("{:.4f}", p);
}

std::string tex_escape(const std::string& s) {
  std::string out;
  for (char ch : s) {
    if (ch == '_' || ch == '%' || ch == '&' || ch == '#') out += '\\';
    out += ch;
  }
  return out;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

/// Rows of cells → text in the chosen format (the first row is the header).
std::string render(const std::vector<std::vector<std::string>>& rows, const std::string& format,
                   std::size_t text_columns) {
  std::string out;
  if (format == "csv") {
    for (const auto& row : rows) {
      for (std::size_t i = 0; i < row.size(); ++i) out += (i ? "," : "") + csv_field(row[i]);
      out += "\n";
    }
    return out;
  }
  if (format == "tex") {
    out += "\\begin{tabular}{" + std::string(text_columns, 'l') +
           std::string(rows.front().size() - text_columns, 'r') + "}\n\\hline\n";
    for (std::size_t r = 0; r < rows.size(); ++r) {
      for (std::size_t i = 0; i < rows[r].size(); ++i) {
        std::string cell = tex_escape(rows[r][i]);
        for (const auto& [from, to] : {std::pair<std::string, std::string>{"±", "$\\pm$"},
                                       {"↑", "$\\uparrow$"}, {"↓", "$\\downarrow$"}}) {
          for (auto at = cell.find(from); at != std::string::npos; at = cell.find(from, at + to.size()))
            cell.replace(at, from.size(), to);
        }
        out += (i ? " & " : "") + cell;
      }
      out += " \\\\\n";
      if (r == 0) out += "\\hline\n";
    }
    return out + "\\hline\n\\end{tabular}\n";
  }
  for (std::size_t r = 0; r < rows.size(); ++r) {
    out += "|";
    for (const auto& cell : rows[r]) out += " " + cell + " |";
    out += "\n";
    if (r == 0) {
      out += "|";
      for (std::size_t i = 0; i < rows[r].size(); ++i) out += i < text_columns ? "---|" : "---:|";
      out += "\n";
    }
  }
  return out;
}

/// The first character where two runs' character lists differ, for the error message.
std::string first_difference(const RunResult& run, const RunResult& ref) {
  for (std::size_t i = 0; i < std::min(run.characters.size(), ref.characters.size()); ++i) {
    if (run.characters[i] != ref.characters[i]) {
      return "'" + run.characters[i] + "' where " + ref.dir.string() + " has '" +
             ref.characters[i] + "'";
    }
  }
  return "(count " + std::to_string(run.characters.size()) + " vs " +
         std::to_string(ref.characters.size()) + ")";
}

void require_same_characters(const RunResult& run, const RunResult& ref) {
  if (run.characters == ref.characters) return;
  throw Error("table: " + run.dir.string() + " was evaluated on other characters than " +
              ref.dir.string() + ": " + first_difference(run, ref) +
              "; evaluate every run on the same dataset, split and part");
}

void require_metrics(const RunResult& run, const std::vector<std::string>& metrics) {
  for (const auto& m : metrics) {
    if (!run.values.count(m)) {
      throw Error("table: " + run.dir.string() + " has no metric '" + m + "' in eval_" +
                  run.part + ".json");
    }
  }
}

void require_format(const TableOptions& options) {
  if (options.format != "md" && options.format != "csv" && options.format != "tex") {
    throw Error("table: unknown format '" + options.format + "'; choose md, csv or tex");
  }
}

/// "character" for "characters", "skeleton family" for "skeleton families".
std::string singular(const std::string& plural) {
  if (plural.size() > 3 && plural.compare(plural.size() - 3, 3, "ies") == 0) {
    return plural.substr(0, plural.size() - 3) + "y";
  }
  return !plural.empty() && plural.back() == 's' ? plural.substr(0, plural.size() - 1) : plural;
}

/// What units averaged over, after their count: " (each the mean over its characters; 86
/// characters)", or nothing for plain characters.
std::string units_note(const RunResult& run) {
  if (run.members == 0) return "";
  return fmt::format(" (each the mean over its characters; {} characters)", run.members);
}

/// The mark of a run made (or resumed) by a build from a modified tree.
std::string dirty_mark(const RunResult& run) { return run.dirty ? "†" : ""; }

/// The note under a Markdown table with a marked run.
const char* const kDirtyNote =
    "† made or resumed by a build from a modified source tree (`git_dirty` in the run's "
    "env.json): its commit alone does not name its code; `git_modified` and `git_diff_sha256` "
    "there say how it differed (runs before 2026-12-03 recorded only the flag).\n";

/// One row of a table: a run, or (group_runs) every run of one experiment, all on the same
/// characters.
struct Row {
  std::string label;
  std::vector<const RunResult*> runs;

  std::string run_ids() const {
    std::string ids;
    for (const auto* r : runs) ids += (ids.empty() ? "" : ", ") + r->run_id + dirty_mark(*r);
    return ids;
  }
  bool any_dirty() const {
    return std::any_of(runs.begin(), runs.end(), [](const RunResult* r) { return r->dirty; });
  }
  /// Each character's mean over the runs (NaN where every run's value is NaN).
  std::vector<double> character_means(const std::string& metric) const {
    const std::size_t n = runs.front()->characters.size();
    std::vector<double> out(n, std::nan(""));
    for (std::size_t c = 0; c < n; ++c) {
      std::vector<double> x;
      for (const auto* r : runs) x.push_back(r->values.at(metric)[c]);
      out[c] = stats_of(x).mean;
    }
    return out;
  }
  /// One run: mean ± sd over characters; several: mean ± sd across the runs of their means.
  MeanSd shown(const std::string& metric) const {
    if (runs.size() == 1) return stats_of(runs.front()->values.at(metric));
    std::vector<double> means;
    for (const auto* r : runs) means.push_back(stats_of(r->values.at(metric)).mean);
    return stats_of(means);
  }
};

/// The one-way ANOVA cell "F (p)" of two per-character value lists, or "n/a" when too few
/// characters have the metric defined (a metric undefined for some is tested on the others).
std::optional<eval::Anova> anova_of(const std::vector<double>& a, const std::vector<double>& b) {
  const auto x = defined(a), y = defined(b);
  if (x.empty() || y.empty() || x.size() + y.size() < 3) return std::nullopt;
  return eval::one_way_anova({x, y});
}

/// The paired t-test of two per-character value lists on the same characters (row − reference),
/// or nothing when fewer than two characters have both values defined.
std::optional<eval::PairedT> paired_of(const std::vector<double>& reference, const std::vector<double>& b) {
  std::size_t pairs = 0;
  for (std::size_t i = 0; i < std::min(reference.size(), b.size()); ++i) {
    pairs += !std::isnan(reference[i]) && !std::isnan(b[i]);
  }
  if (reference.size() != b.size() || pairs < 2) return std::nullopt;
  return eval::paired_t_test(reference, b);
}

/// The metric definitions quoted under a Markdown table (the first run's).
std::string definitions_text(const RunResult& ref) {
  if (!ref.metric_definitions.empty()) {
    return "Metrics (the first run's evaluation): " + ref.metric_definitions + "\n";
  }
  if (!ref.metrics_yaml.empty() && ref.metrics_yaml != "[]") {
    return "Metric definitions and thresholds (the first run's config):\n\n```yaml\n" +
           ref.metrics_yaml + (ref.metrics_yaml.back() == '\n' ? "" : "\n") + "```\n";
  }
  return "";
}

}  // namespace

RunResult load_run_result(const fs::path& dir, const std::string& part) {
  const fs::path file = dir / ("eval_" + part + ".json");
  if (!fs::exists(file)) {
    throw IoError(file.string() + ": not found; evaluate the run first: skinlab eval " +
                  dir.string() + " --split " + part);
  }
  RunResult r;
  r.dir = dir;
  try {
    const auto j = nlohmann::json::parse(read_file(file));
    r.label = j.at("experiment").get<std::string>();
    r.task = j.value("task", std::string("skinning"));
    r.run_id = j.at("run").get<std::string>();
    r.dataset = j.at("dataset").get<std::string>();
    r.split = j.at("split").get<std::string>();
    r.part = j.at("part").get<std::string>();
    r.checkpoint = j.at("checkpoint").get<std::string>();
    r.epoch = j.at("epoch").get<int>();
    if (j.contains("metric_definitions")) {
      r.metric_definitions = j.at("metric_definitions").get<std::string>();
    }
    for (const auto& c : j.at("per_character")) {
      r.characters.push_back(c.at("character").get<std::string>());
      for (const auto& [name, v] : c.at("values").items()) {
        r.values[name].push_back(v.is_null() ? std::nan("") : v.get<double>());
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw IoError(file.string() + ": not an evaluation report of this build (" + e.what() + ")");
  }
  for (const auto& [name, v] : r.values) {
    if (v.size() != r.characters.size()) {
      throw IoError(file.string() + ": metric '" + name + "' is missing for some characters");
    }
  }
  // A run made or resumed by a build from a modified tree (core/environment.hpp, git_json).
  const fs::path env = dir / "env.json";
  if (fs::exists(env)) {
    try {
      const auto j = nlohmann::json::parse(read_file(env));
      r.dirty = j.value("git_dirty", false);
      for (const auto& resume : j.value("resumes", nlohmann::json::array())) {
        r.dirty = r.dirty || resume.value("git_dirty", false);
      }
    } catch (const nlohmann::json::exception& e) {
      throw IoError(env.string() + ": not a run environment record (" + e.what() + ")");
    }
  }
  const fs::path config = dir / "config.yaml";
  if (fs::exists(config)) {
    const config::Node metrics = config::Config::load(config.string()).root()["metrics"];
    if (metrics.exists()) r.metrics_yaml = metrics.to_yaml();
  }
  return r;
}

void count_as_same_data(std::vector<RunResult>& runs, const std::string& from, const std::string& to) {
  int renamed = 0;
  for (auto& run : runs) {
    if (run.dataset == from) {
      run.dataset = to;
      ++renamed;
    }
  }
  if (renamed == 0) throw Error("table: no run was evaluated on `" + from + "` (--same-data)");
}

void average_over_units(RunResult& run, const std::map<std::string, std::string>& unit_of,
                        const std::string& unit) {
  std::vector<std::string> units;
  std::vector<std::size_t> index_of(run.characters.size());
  for (std::size_t c = 0; c < run.characters.size(); ++c) {
    const auto at = unit_of.find(run.characters[c]);
    if (at == unit_of.end()) {
      throw Error("table: " + run.dir.string() + ": character '" + run.characters[c] +
                  "' has no unit among the " + unit + " of `" + run.dataset +
                  "` (its evaluation report's dataset)");
    }
    const auto found = std::find(units.begin(), units.end(), at->second);
    index_of[c] = static_cast<std::size_t>(found - units.begin());
    if (found == units.end()) units.push_back(at->second);
  }
  for (auto& [metric, values] : run.values) {
    std::vector<std::vector<double>> members(units.size());
    for (std::size_t c = 0; c < values.size(); ++c) members[index_of[c]].push_back(values[c]);
    values.clear();
    for (const auto& m : members) values.push_back(stats_of(m).mean);
  }
  run.members = run.characters.size();
  run.characters = std::move(units);
  run.unit = unit;
}

std::string make_table(const std::vector<RunResult>& runs, const TableOptions& options) {
  if (runs.empty()) throw Error("table: no runs given");
  if (options.across_splits) return make_split_table(runs, options);
  require_format(options);
  const RunResult& ref = runs.front();
  for (const auto& run : runs) {
    require_same_characters(run, ref);
    require_metrics(run, options.metrics);
  }
  std::vector<Row> rows;
  for (const auto& run : runs) {
    auto same = std::find_if(rows.begin(), rows.end(), [&](const Row& r) { return r.label == run.label; });
    if (options.group_runs && same != rows.end()) {
      same->runs.push_back(&run);
    } else {
      rows.push_back({run.label, {&run}});
    }
  }
  const bool grouped = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return r.runs.size() > 1; });

  std::vector<std::vector<std::string>> main{{"Method", grouped ? "Runs" : "Run"}};
  for (const auto& m : options.metrics) main.front().push_back(eval::value_display(m).column_header());
  for (const auto& row : rows) {
    std::vector<std::string> cells{row.label, row.run_ids()};
    for (const auto& m : options.metrics) {
      const eval::ValueDisplay c = eval::value_display(m);
      const MeanSd s = row.shown(m);
      cells.push_back(value_text(s.mean, c) + " ± " + value_text(s.sd, c));
    }
    main.push_back(std::move(cells));
  }

  std::string out;
  const bool md = options.format == "md";
  if (md && !options.title.empty()) out += "### " + options.title + "\n\n";
  if (options.format == "tex") out += "\\begin{table}\n\\centering\n";
  out += render(main, options.format, 2);
  // Rows of one experiment (e.g. seeds not grouped) are told apart by their run ids.
  auto name = [&](const Row& row) {
    int same = 0;
    for (const auto& other : rows) same += other.label == row.label;
    return same > 1 ? row.label + " (" + row.run_ids() + ")" : row.label;
  };
  // An ANOVA needs two characters per run (a CI smoke run on one test character has none).
  if (rows.size() > 1 && ref.characters.size() > 1) {
    std::vector<std::vector<std::string>> anova{{"One-way ANOVA vs " + name(rows.front())}};
    std::vector<std::vector<std::string>> paired{{"Paired t-test vs " + name(rows.front())}};
    for (const auto& m : options.metrics) {
      anova.front().push_back(eval::value_display(m).column_header() + " F (p)");
      paired.front().push_back(eval::value_display(m).column_header() + " t (p)");
    }
    for (std::size_t r = 1; r < rows.size(); ++r) {
      std::vector<std::string> a_cells{name(rows[r])}, t_cells{name(rows[r])};
      for (const auto& m : options.metrics) {
        const auto reference = rows.front().character_means(m), values = rows[r].character_means(m);
        const auto a = anova_of(reference, values);
        a_cells.push_back(a ? fmt::format("{:.4f} ({})", a->F, p_text(a->p)) : "n/a");
        const auto t = paired_of(reference, values);
        t_cells.push_back(t ? fmt::format("{:.4f} ({})", t->t, p_text(t->p)) : "n/a");
      }
      anova.push_back(std::move(a_cells));
      paired.push_back(std::move(t_cells));
    }
    const std::string gap = md || options.format == "csv" ? "\n" : "\\medskip\n";
    out += gap + render(anova, options.format, 1);
    out += gap + render(paired, options.format, 1);
  }
  if (options.format == "tex" && !options.title.empty()) {
    out += "\\caption{" + tex_escape(options.title) + "}\n";
  }
  if (options.format == "tex") out += "\\end{table}\n";
  if (md) {
    out += fmt::format("\n{} {}{} of the {} part of split '{}' of `{}`; mean ± sample "
                       "standard deviation over {}", ref.characters.size(), ref.unit,
                       units_note(ref), ref.part, ref.split, ref.dataset, ref.unit);
    if (grouped) {
      out += "; a row of several runs (seeds) gives the mean ± sample standard deviation across "
             "the runs of their means, and its ANOVA uses each " + singular(ref.unit) +
             "'s mean over the runs";
    }
    out += ".\n";
    if (rows.size() > 1 && ref.characters.size() > 1) {
      out += "The one-way ANOVA (the paper's test, Sec. 4.5) treats the two rows' values as "
             "independent samples; the paired t-test uses each " + singular(ref.unit) +
             "'s difference (row − " + name(rows.front()) + ", t > 0 where the row is larger), as "
             "both rows score the same " + ref.unit + "; p is two-sided.\n";
    }
    if (std::any_of(rows.begin(), rows.end(), [](const Row& r) { return r.any_dirty(); })) out += kDirtyNote;
    out += definitions_text(ref);
    if (!options.command.empty()) out += "Generated by `" + options.command + "`.\n";
  }
  return out;
}

std::string make_split_table(const std::vector<RunResult>& runs, const TableOptions& options) {
  if (runs.empty()) throw Error("table: no runs given");
  require_format(options);
  for (const auto& run : runs) require_metrics(run, options.metrics);

  // Columns: the test sets, by dataset and split, in order of appearance.
  struct Column {
    std::string dataset, split;
    std::string name;
  };
  std::vector<Column> columns;
  auto column_of = [&](const RunResult& run) {
    for (std::size_t i = 0; i < columns.size(); ++i) {
      if (columns[i].dataset == run.dataset && columns[i].split == run.split) return i;
    }
    columns.push_back({run.dataset, run.split, ""});
    return columns.size() - 1;
  };
  std::vector<std::string> labels;
  std::map<std::pair<std::string, std::size_t>, Row> cells;
  for (const auto& run : runs) {
    const std::size_t col = column_of(run);
    if (std::find(labels.begin(), labels.end(), run.label) == labels.end()) labels.push_back(run.label);
    Row& cell = cells[{run.label, col}];
    if (!cell.runs.empty()) {
      if (!options.group_runs) {
        throw Error("table: " + cell.runs.front()->dir.string() + " and " + run.dir.string() +
                    " are both '" + run.label + "' on split '" + run.split + "' of `" +
                    run.dataset + "`; group them (seeds) with --group-runs");
      }
      require_same_characters(run, *cell.runs.front());
    }
    cell.label = run.label;
    cell.runs.push_back(&run);
  }
  // Named by split; by dataset too when the test sets come from several dataset files.
  const bool one_dataset = std::all_of(columns.begin(), columns.end(), [&](const Column& c) {
    return c.dataset == columns.front().dataset;
  });
  for (auto& c : columns) {
    c.name = one_dataset ? c.split
                         : fs::path(c.dataset).stem().string() + (c.split == "random" ? "" : " " + c.split);
  }
  // Every method of a column on the characters of the column's first method.
  std::vector<const RunResult*> column_ref(columns.size(), nullptr);
  for (const auto& run : runs) {
    const RunResult*& first = column_ref[column_of(run)];
    if (first == nullptr) first = &run;
    require_same_characters(run, *first);
  }
  const bool union_column = columns.size() > 1;
  const std::string& reference = labels.front();
  // What the columns are: the test sets, or the validation (or training) sets for --part val.
  const std::string& part = runs.front().part;
  const std::string set = (part == "val" ? "validation" : part) + " set";
  auto find_cell = [&](const std::string& label, std::size_t col) -> const Row* {
    const auto at = cells.find({label, col});
    return at == cells.end() ? nullptr : &at->second;
  };
  auto any_dirty_of = [&](const std::string& label) {
    for (std::size_t col = 0; col < columns.size(); ++col) {
      const Row* cell = find_cell(label, col);
      if (cell != nullptr && cell->any_dirty()) return true;
    }
    return false;
  };
  // The union's per-character values of a method evaluated on every column (else empty).
  auto pooled = [&](const std::string& label, const std::string& metric) {
    std::vector<double> all;
    for (std::size_t col = 0; col < columns.size(); ++col) {
      const Row* cell = find_cell(label, col);
      if (cell == nullptr) return std::vector<double>{};
      const auto v = cell->character_means(metric);
      all.insert(all.end(), v.begin(), v.end());
    }
    return all;
  };

  std::string out;
  const bool md = options.format == "md";
  if (md && !options.title.empty()) out += "### " + options.title + "\n\n";
  if (options.format == "tex") out += "\\begin{table}\n\\centering\n";
  for (std::size_t mi = 0; mi < options.metrics.size(); ++mi) {
    const std::string& m = options.metrics[mi];
    const eval::ValueDisplay display = eval::value_display(m);
    std::vector<std::vector<std::string>> table{{display.column_header()}};
    for (const auto& c : columns) table.front().push_back(c.name);
    if (union_column) table.front().push_back("all " + set + "s");
    auto cell_text = [&](const std::vector<double>& values, const std::vector<double>& ref_values,
                         bool is_reference) {
      std::string text = value_text(stats_of(values).mean, display);
      if (!is_reference) {
        const auto a = anova_of(ref_values, values);
        const auto t = paired_of(ref_values, values);
        if (a && t) {
          text += " (p " + p_text(a->p) + "; paired " + p_text(t->p) + ")";
        } else if (a) {
          text += " (p " + p_text(a->p) + ")";
        }
      }
      return text;
    };
    for (const auto& label : labels) {
      std::vector<std::string> row{label};
      for (std::size_t col = 0; col < columns.size(); ++col) {
        const Row* cell = find_cell(label, col);
        const Row* ref_cell = find_cell(reference, col);
        if (cell == nullptr) {
          row.push_back("—");
          continue;
        }
        row.push_back(cell_text(cell->character_means(m),
                                ref_cell ? ref_cell->character_means(m) : std::vector<double>{},
                                label == reference || ref_cell == nullptr) +
                      (cell->any_dirty() ? "†" : ""));
      }
      if (union_column) {
        const auto all = pooled(label, m);
        const auto ref_all = pooled(reference, m);
        row.push_back(all.empty() ? "—"
                                  : cell_text(all, ref_all, label == reference || ref_all.empty()) +
                                        (any_dirty_of(label) ? "†" : ""));
      }
      table.push_back(std::move(row));
    }
    if (mi > 0) out += md || options.format == "csv" ? "\n" : "\\medskip\n";
    out += render(table, options.format, 1);
  }
  if (options.format == "tex" && !options.title.empty()) {
    out += "\\caption{" + tex_escape(options.title) + "}\n";
  }
  if (options.format == "tex") out += "\\end{table}\n";
  if (md) {
    const std::string& unit = runs.front().unit;
    out += "\nMean over each " + set + "'s " + unit;
    if (options.group_runs) {
      out += " (a method with several runs, e.g. seeds: of each " + singular(unit) +
             "'s mean over its runs)";
    }
    out += "; (p …; paired …): two-sided p of the one-way ANOVA (the paper's test, Sec. 4.5) and "
           "of the paired t-test over the same " + unit + " against " + reference + ". The " + set + "s: ";
    for (std::size_t col = 0; col < columns.size(); ++col) {
      const RunResult& r = *column_ref[col];
      out += fmt::format("{}{}: {} {}{}, {} part of split '{}' of `{}`", col ? "; " : "",
                         columns[col].name, r.characters.size(), r.unit, units_note(r), r.part,
                         r.split, r.dataset);
    }
    out += ".\n";
    if (std::any_of(runs.begin(), runs.end(), [](const RunResult& r) { return r.dirty; })) out += kDirtyNote;
    out += definitions_text(runs.front());
    if (!options.command.empty()) out += "Generated by `" + options.command + "`.\n";
  }
  return out;
}

}  // namespace skinlab::report

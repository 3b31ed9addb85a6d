#include "framework/report/table.hpp"

#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/eval/anova.hpp"
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
  const fs::path config = dir / "config.yaml";
  if (fs::exists(config)) {
    const config::Node metrics = config::Config::load(config.string()).root()["metrics"];
    if (metrics.exists()) r.metrics_yaml = metrics.to_yaml();
  }
  return r;
}

std::string make_table(const std::vector<RunResult>& runs, const TableOptions& options) {
  if (runs.empty()) throw Error("table: no runs given");
  if (options.format != "md" && options.format != "csv" && options.format != "tex") {
    throw Error("table: unknown format '" + options.format + "'; choose md, csv or tex");
  }
  const RunResult& ref = runs.front();
  for (const auto& run : runs) {
    if (run.characters != ref.characters) {
      std::string first = "(count " + std::to_string(run.characters.size()) + " vs " +
                          std::to_string(ref.characters.size()) + ")";
      for (std::size_t i = 0; i < std::min(run.characters.size(), ref.characters.size()); ++i) {
        if (run.characters[i] != ref.characters[i]) {
          first = "'" + run.characters[i] + "' where " + ref.dir.string() + " has '" +
                  ref.characters[i] + "'";
          break;
        }
      }
      throw Error("table: " + run.dir.string() + " was evaluated on other characters than " +
                  ref.dir.string() + ": " + first + "; evaluate every run on the same dataset, "
                  "split and part");
    }
    for (const auto& m : options.metrics) {
      if (!run.values.count(m)) {
        throw Error("table: " + run.dir.string() + " has no metric '" + m + "' in eval_" +
                    run.part + ".json");
      }
    }
  }

  std::vector<std::vector<std::string>> main{{"Method", "Run"}};
  for (const auto& m : options.metrics) main.front().push_back(eval::value_display(m).column_header());
  for (const auto& run : runs) {
    std::vector<std::string> row{run.label, run.run_id};
    for (const auto& m : options.metrics) {
      const eval::ValueDisplay c = eval::value_display(m);
      const MeanSd s = stats_of(run.values.at(m));
      row.push_back(value_text(s.mean, c) + " ± " + value_text(s.sd, c));
    }
    main.push_back(std::move(row));
  }

  std::string out;
  const bool md = options.format == "md";
  if (md && !options.title.empty()) out += "### " + options.title + "\n\n";
  if (options.format == "tex") out += "\\begin{table}\n\\centering\n";
  out += render(main, options.format, 2);
  // An ANOVA needs two characters per run (a CI smoke run on one test character has none).
  if (runs.size() > 1 && ref.characters.size() > 1) {
    // Runs of one experiment (e.g. seeds) are told apart by their run id.
    auto name = [&](const RunResult& run) {
      int same = 0;
      for (const auto& other : runs) same += other.label == run.label;
      return same > 1 ? run.label + " (" + run.run_id + ")" : run.label;
    };
    std::vector<std::vector<std::string>> anova{{"One-way ANOVA vs " + name(ref)}};
    for (const auto& m : options.metrics) anova.front().push_back(eval::value_display(m).column_header() + " F (p)");
    for (std::size_t r = 1; r < runs.size(); ++r) {
      std::vector<std::string> row{name(runs[r])};
      for (const auto& m : options.metrics) {
        // A metric undefined for some characters (NaN) is tested on the others.
        const auto x = defined(ref.values.at(m)), y = defined(runs[r].values.at(m));
        if (x.empty() || y.empty() || x.size() + y.size() < 3) {
          row.push_back("n/a");
          continue;
        }
        const auto a = eval::one_way_anova({x, y});
        row.push_back(fmt::format("{:.4f} ({})", a.F, p_text(a.p)));
      }
      anova.push_back(std::move(row));
    }
    out += md ? "\n" : options.format == "csv" ? "\n" : "\\medskip\n";
    out += render(anova, options.format, 1);
  }
  if (options.format == "tex" && !options.title.empty()) {
    out += "\\caption{" + tex_escape(options.title) + "}\n";
  }
  if (options.format == "tex") out += "\\end{table}\n";
  if (md) {
    out += fmt::format("\n{} characters of the {} part of split '{}' of `{}`; mean ± sample "
                       "standard deviation over characters", ref.characters.size(), ref.part,
                       ref.split, ref.dataset);
    out += ".\n";
    if (!ref.metric_definitions.empty()) {
      out += "Metrics (the first run's evaluation): " + ref.metric_definitions + "\n";
    } else if (!ref.metrics_yaml.empty() && ref.metrics_yaml != "[]") {
      out += "Metric definitions and thresholds (the first run's config):\n\n```yaml\n" +
             ref.metrics_yaml + (ref.metrics_yaml.back() == '\n' ? "" : "\n") + "```\n";
    }
    if (!options.command.empty()) out += "Generated by `" + options.command + "`.\n";
  }
  return out;
}

}  // namespace skinlab::report

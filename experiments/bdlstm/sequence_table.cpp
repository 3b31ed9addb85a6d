#include "experiments/bdlstm/sequence_table.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <map>
#include <regex>
#include <set>

#include "framework/core/error.hpp"
#include "framework/eval/paired_t.hpp"

namespace skinlab::bdlstm {

namespace {

struct Row {
  std::string label;
  std::map<std::pair<std::string, int>, double> cells;  // (character, horizon) → mm
};

Row& row_named(std::vector<Row>& rows, const std::string& label) {
  for (Row& r : rows) {
    if (r.label == label) return r;
  }
  rows.push_back({label, {}});
  return rows.back();
}

std::string ordinal(int n) {
  const int tens = n % 100, ones = n % 10;
  const char* suffix = tens >= 11 && tens <= 13 ? "th" : ones == 1 ? "st" : ones == 2 ? "nd" : ones == 3 ? "rd" : "th";
  return std::to_string(n) + suffix;
}

void add_unique(std::vector<std::string>& list, const std::string& value) {
  if (std::find(list.begin(), list.end(), value) == list.end()) list.push_back(value);
}

std::string cell_text(const Row& r, const std::string& ch, int h, int decimals, const char* missing) {
  const auto it = r.cells.find({ch, h});
  return it == r.cells.end() ? std::string(missing) : fmt::format("{:.{}f}", it->second, decimals);
}

/// The characters of `r` at horizon `h`, in `characters`' order, and its values there.
std::vector<std::pair<std::string, double>> column(const Row& r, const std::vector<std::string>& characters,
                                                   int h) {
  std::vector<std::pair<std::string, double>> out;
  for (const auto& ch : characters) {
    const auto it = r.cells.find({ch, h});
    if (it != r.cells.end()) out.emplace_back(ch, it->second);
  }
  return out;
}

/// Qiao et al.'s Table 1 layout for one character: one column per horizon.
std::string single_character_layout(const std::vector<Row>& rows, const Row& starts,
                                    const std::string& character, const std::set<int>& horizons) {
  std::string out = "| method |", rule = "|---|";
  for (int h : horizons) {
    out += fmt::format(" {} {} |", character, ordinal(h));
    rule += "---:|";
  }
  out += "\n" + rule + "\n";
  for (const Row& r : rows) {
    out += "| " + r.label + " |";
    for (int h : horizons) out += " " + cell_text(r, character, h, 2, "—") + " |";
    out += "\n";
  }
  out += "\nMean vertex error in mm (characters scaled to 1 m). Predictions per cell:";
  for (int h : horizons) {
    out += fmt::format(" {} {}: {};", character, ordinal(h), cell_text(starts, character, h, 0, "—"));
  }
  out.back() = '.';
  return out + "\n";
}

/// Tables 1-2 over several characters (the paper trains one network per mesh, Sec. 3.2): one
/// row per method, per horizon the mean over the characters that reach it and the two-sided
/// paired t-test over those characters against the first row (eval/paired_t.hpp).
std::string mean_layout(const std::vector<Row>& rows, const Row& starts,
                        const std::vector<std::string>& characters, const std::set<int>& horizons) {
  std::string out = "| method |", rule = "|---|";
  for (int h : horizons) {
    out += fmt::format(" {} | p |", ordinal(h));
    rule += "---:|---:|";
  }
  out += "\n" + rule + "\n";
  std::map<int, std::vector<std::pair<std::string, double>>> reached;  // horizon → predictions
  for (int h : horizons) reached[h] = column(starts, characters, h);
  const Row& reference = rows.front();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    const bool floor = i + 1 == rows.size();  // the representation's floor: not a method
    out += "| " + r.label + " |";
    for (int h : horizons) {
      const auto values = column(r, characters, h);
      if (values.empty()) {
        out += " — | |";
        continue;
      }
      double sum = 0;
      for (const auto& v : values) sum += v.second;
      out += fmt::format(" {:.2f}", sum / static_cast<double>(values.size()));
      if (values.size() < reached[h].size()) {
        out += fmt::format(" ({} of {})", values.size(), reached[h].size());
      }
      out += " |";
      if (i == 0 || floor) {
        out += " |";
        continue;
      }
      // Paired over the characters both rows report at this horizon.
      std::vector<double> a, b;
      for (const auto& [ch, v] : values) {
        const auto it = reference.cells.find({ch, h});
        if (it == reference.cells.end()) continue;
        a.push_back(it->second);
        b.push_back(v);
      }
      if (a.size() < 2) {
        out += " |";
        continue;
      }
      const eval::PairedT t = eval::paired_t_test(a, b);
      out += std::isnan(t.p) ? std::string(" |") : fmt::format(" {:.2g} |", t.p);
    }
    out += "\n";
  }
  out += fmt::format("\nMean over characters of each character's mean vertex error in mm (characters "
                     "scaled to 1 m); p: two-sided paired t-test over the same characters against "
                     "{}. Characters reaching each horizon (predictions):",
                     reference.label);
  for (const auto& [h, predictions] : reached) {
    double sum = 0;
    for (const auto& v : predictions) sum += v.second;
    out += fmt::format(" {}: {} ({:.0f});", ordinal(h), predictions.size(), sum);
  }
  out.back() = '.';
  out += "\nCharacters: " + fmt::format("{}", fmt::join(characters, ", ")) +
         ". Per character: the CSV beside this table.\n";
  return out;
}

}  // namespace

std::string sequence_table(const std::vector<report::RunResult>& runs,
                           const report::TableOptions& options) {
  if (runs.empty()) throw Error("sequence table: no run given");
  if (options.format != "md" && options.format != "csv") {
    throw Error("sequence table: format '" + options.format + "' is not supported (md or csv)");
  }
  const std::regex error_key(R"(e(\d+)_(\d)if_mm)"), floor_key(R"(floor(\d+)_mm)"),
      starts_key(R"(starts(\d+))");
  std::vector<Row> rows;
  Row floor{"ACAP floor (true features decoded)", {}}, starts{"predictions", {}};
  std::vector<std::string> characters;
  std::set<int> horizons;
  for (const report::RunResult& run : runs) {
    if (run.task != "sequence") {
      throw Error("sequence table: " + run.dir.string() + " is a " + run.task +
                  " run; a table mixes runs of one task");
    }
    bool any = false;
    for (const auto& [key, values] : run.values) {
      std::smatch m;
      for (std::size_t c = 0; c < run.characters.size(); ++c) {
        const double v = values[c];
        if (std::isnan(v)) continue;
        const std::string& ch = run.characters[c];
        if (std::regex_match(key, m, error_key)) {
          const int h = std::stoi(m[1]);
          const std::string label = fmt::format("{} ({} IF)", run.label, m[2].str());
          if (!row_named(rows, label).cells.emplace(std::pair{ch, h}, v).second) {
            throw Error("sequence table: two runs of experiment '" + run.label + "' report '" +
                        ch + "' (the second: " + run.dir.string() +
                        "); give the variants their own `experiment` names");
          }
          horizons.insert(h);
          add_unique(characters, ch);
          any = true;
        } else if (std::regex_match(key, m, floor_key)) {
          floor.cells.emplace(std::pair{ch, std::stoi(m[1])}, v);
        } else if (std::regex_match(key, m, starts_key)) {
          starts.cells.emplace(std::pair{ch, std::stoi(m[1])}, v);
        }
      }
    }
    if (!any) throw Error("sequence table: " + run.dir.string() + " reports no e<h>_<u>if_mm value");
  }
  rows.push_back(floor);
  std::string out;
  if (options.format == "md") {
    if (!options.title.empty()) out += "### " + options.title + "\n\n";
    if (characters.size() > 1) {
      out += mean_layout(rows, starts, characters, horizons);
    } else {
      out += single_character_layout(rows, starts, characters.front(), horizons);
    }
    if (!runs.front().metric_definitions.empty()) out += "\n" + runs.front().metric_definitions + ".\n";
    if (!options.command.empty()) out += "\nGenerated by `" + options.command + "`.\n";
  } else {
    out += "method,character,horizon,error_mm,predictions\n";
    for (const Row& r : rows) {
      for (const auto& ch : characters) {
        for (int h : horizons) {
          if (r.cells.count({ch, h})) {
            out += fmt::format("\"{}\",{},{},{},{}\n", r.label, ch, h, cell_text(r, ch, h, 6, ""),
                               cell_text(starts, ch, h, 0, ""));
          }
        }
      }
    }
  }
  return out;
}

}  // namespace skinlab::bdlstm

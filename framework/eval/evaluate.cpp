#include "framework/eval/evaluate.hpp"

#include <cmath>
#include <limits>

#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"

namespace skinlab::eval {

std::vector<std::shared_ptr<Metric>> make_metrics(const config::Node& list) {
  if (!list.is_sequence() || list.size() == 0) {
    list.fail(
        "expected a non-empty list of metrics, e.g. [{type: precision_recall}, "
        "{type: avg_l1}, {type: deformation_error}]");
  }
  std::vector<std::shared_ptr<Metric>> metrics;
  std::map<std::string, std::size_t> owner;  // output name → index of the entry reporting it
  for (std::size_t i = 0; i < list.size(); ++i) {
    const config::Node entry = list[i];
    auto metric = metric_registry().create(entry);
    for (const auto& name : metric->names()) {
      const auto [it, inserted] = owner.emplace(name, i);
      if (!inserted) {
        entry.fail("metric '" + entry.required_type("metric") + "' reports '" + name + "', which " +
                   list[it->second].path() + " (type '" + list[it->second].required_type("metric") +
                   "') reports already; list each metric once");
      }
    }
    metrics.push_back(std::move(metric));
  }
  return metrics;
}

namespace {

std::string join_names(const std::map<std::string, double>& values) {
  std::string out;
  for (const auto& [name, value] : values) out += (out.empty() ? "" : ", ") + name;
  return "{" + out + "}";
}

}  // namespace

std::map<std::string, double> mean_over_characters(
    const std::vector<std::map<std::string, double>>& per_character) {
  std::map<std::string, double> sum;
  std::map<std::string, long> counted;  // characters for which a value is defined (not NaN)
  if (per_character.empty()) return sum;
  for (std::size_t c = 0; c < per_character.size(); ++c) {
    const auto& values = per_character[c];
    bool same = values.size() == per_character.front().size();
    for (auto a = values.begin(), b = per_character.front().begin(); same && a != values.end();
         ++a, ++b) {
      same = a->first == b->first;
    }
    if (!same) {
      throw Error("mean_over_characters: character " + std::to_string(c) + " reports " +
                  join_names(values) + " but character 0 reports " +
                  join_names(per_character.front()));
    }
    for (const auto& [name, value] : values) {
      sum[name] += std::isnan(value) ? 0.0 : value;
      if (!std::isnan(value)) ++counted[name];
    }
  }
  for (auto& [name, value] : sum) {
    value = counted[name] > 0 ? value / static_cast<double>(counted[name])
                              : std::numeric_limits<double>::quiet_NaN();
  }
  return sum;
}

}  // namespace skinlab::eval

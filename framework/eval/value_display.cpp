#include "framework/eval/value_display.hpp"

#include <map>
#include <mutex>
#include <vector>

#include "framework/core/error.hpp"

namespace skinlab::eval {

namespace {

struct Declarations {
  std::mutex mutex;
  std::map<std::string, std::pair<ValueDisplay, std::string>> by_name;  // display, site
  std::vector<std::string> conflicts;
};

Declarations& declarations() {
  static Declarations d;
  return d;
}

bool same(const ValueDisplay& a, const ValueDisplay& b) {
  return a.header == b.header && a.unit == b.unit && a.higher_better == b.higher_better &&
         a.percent == b.percent && a.decimals == b.decimals;
}

}  // namespace

std::string ValueDisplay::column_header() const {
  if (!declared) return name;
  return header + (unit.empty() ? "" : " (" + unit + ")") + (higher_better ? " ↑" : " ↓");
}

void declare_value(ValueDisplay display, const char* site) {
  display.declared = true;
  Declarations& d = declarations();
  const std::lock_guard<std::mutex> lock(d.mutex);
  const auto [it, inserted] = d.by_name.try_emplace(display.name, display, site);
  if (!inserted && !same(it->second.first, display)) {
    d.conflicts.push_back("value '" + display.name + "' is declared differently at " + site +
                          " and at " + it->second.second);
  }
}

ValueDisplay value_display(const std::string& name) {
  Declarations& d = declarations();
  const std::lock_guard<std::mutex> lock(d.mutex);
  if (!d.conflicts.empty()) throw RegistryError(d.conflicts.front());
  const auto it = d.by_name.find(name);
  if (it != d.by_name.end()) return it->second.first;
  ValueDisplay plain;
  plain.name = name;
  plain.header = name;
  return plain;
}

}  // namespace skinlab::eval

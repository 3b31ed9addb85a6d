#pragma once
/// \file
/// How an evaluated value is shown in a comparison table: each metric declares its values'
/// header, unit, direction and precision next to its code (SKINLAB_DECLARE_VALUE), and
/// report/table.cpp reads the declarations instead of knowing any metric.

#include <string>

namespace skinlab::eval {

struct ValueDisplay {
  std::string name;            ///< the value's key in eval_<part>.json, e.g. "precision"
  std::string header;          ///< column header without unit and arrow, e.g. "Precision"
  std::string unit;            ///< shown as " (unit)" after the header; empty for none
  bool higher_better = false;  ///< the arrow: ↑ when higher is better, ↓ otherwise
  bool percent = false;        ///< a fraction shown as a percentage
  int decimals = 4;            ///< digits after the point
  bool declared = false;       ///< set by declare_value; false: a value nobody declared

  /// "<header>[ (<unit>)] ↑|↓"; the bare name for an undeclared value.
  std::string column_header() const;
};

/// Declares how value `display.name` is shown. A second declaration of a name must be the same.
void declare_value(ValueDisplay display, const char* site);
/// The declaration of `name`, or an undeclared one (its bare name, 4 decimals) when none was
/// made. RegistryError when two declarations of one value disagree.
ValueDisplay value_display(const std::string& name);

}  // namespace skinlab::eval

/// At namespace scope in a metric's .cpp: SKINLAB_DECLARE_VALUE({"recall", "Recall", "", true, true, 2});
#define SKINLAB_DECLARE_VALUE(...)                                                             \
  static const bool SKINLAB_VALUE_CONCAT(skinlab_value_, __COUNTER__) =                        \
      (::skinlab::eval::declare_value(::skinlab::eval::ValueDisplay __VA_ARGS__,               \
                                      __FILE__), true)
#define SKINLAB_VALUE_CONCAT_INNER(a, b) a##b
#define SKINLAB_VALUE_CONCAT(a, b) SKINLAB_VALUE_CONCAT_INNER(a, b)

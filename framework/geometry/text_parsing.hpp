#pragma once
/// \file
/// Line-oriented text parsing shared by the OBJ and rig readers: whitespace-split words, comment
/// and blank-line skipping, and "file:line: message" errors.

#include <charconv>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

/// Parses a whole word as a number (no trailing characters). Doubles accept what strtod does.
bool parse_number(std::string_view word, double& out);
bool parse_number(std::string_view word, long& out);

/// Where a line came from; `fail` throws GeometryError("file:line: message").
struct LineContext {
  const std::filesystem::path* file;
  int line;
  [[noreturn]] void fail(const std::string& message) const;
  template <class T>
  T number(std::string_view word, const char* what) const {
    T value{};
    if (!parse_number(word, value)) fail(std::string("bad ") + what + " '" + std::string(word) + "'");
    return value;
  }
};

/// Calls `handle(words, context)` for every line with at least one word that is not a
/// comment (`#`). Words are views into `text`.
void for_each_line(
    const std::string& text, const std::filesystem::path& file,
    const std::function<void(const std::vector<std::string_view>&, const LineContext&)>& handle);

}  // namespace skinlab::geometry

#pragma once
/// \file
/// Small text helpers for error messages that list what exists (the distances a character was
/// prepared with, the splits of a dataset file, the priors of a character, the sources of a
/// split).

#include <string>
#include <string_view>
#include <vector>

namespace skinlab {

/// The elements of a container of strings, in its order, joined with ", "; `none` when it is
/// empty.
template <class Container>
std::string joined(const Container& values, std::string_view none = "none") {
  std::string out;
  for (const auto& value : values) out += (out.empty() ? "" : ", ") + std::string(value);
  return out.empty() ? std::string(none) : out;
}

/// The keys of an associative container, in its order, joined as `joined` does.
template <class Map>
std::string joined_keys(const Map& map, std::string_view none = "none") {
  std::vector<std::string_view> keys;
  for (const auto& entry : map) keys.emplace_back(entry.first);
  return joined(keys, none);
}

}  // namespace skinlab

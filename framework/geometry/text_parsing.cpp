#include "framework/geometry/text_parsing.hpp"

#include <cmath>
#include <cstdlib>

namespace skinlab::geometry {

bool parse_number(std::string_view word, double& out) {
  // strtod (not from_chars) so that "1e-05", "+3", "inf" parse as other tools write them.
  const std::string copy(word);
  char* end = nullptr;
  out = std::strtod(copy.c_str(), &end);
  return !copy.empty() && end == copy.c_str() + copy.size();
}

bool parse_number(std::string_view word, long& out) {
  const char* begin = word.data() + (!word.empty() && word[0] == '+' ? 1 : 0);
  const auto [ptr, ec] = std::from_chars(begin, word.data() + word.size(), out);
  return !word.empty() && ec == std::errc() && ptr == word.data() + word.size();
}

void LineContext::fail(const std::string& message) const {
  throw GeometryError(file->string() + ":" + std::to_string(line) + ": " + message);
}

void for_each_line(
    const std::string& text, const std::filesystem::path& file,
    const std::function<void(const std::vector<std::string_view>&, const LineContext&)>& handle) {
  std::vector<std::string_view> words;
  std::size_t start = 0;
  for (int line = 1; start <= text.size(); ++line) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string_view content(text.data() + start, end - start);
    if (const auto hash = content.find('#'); hash != std::string_view::npos) content = content.substr(0, hash);
    words.clear();
    std::size_t i = 0;
    while (i < content.size()) {
      while (i < content.size() && std::isspace(static_cast<unsigned char>(content[i]))) ++i;
      const std::size_t w = i;
      while (i < content.size() && !std::isspace(static_cast<unsigned char>(content[i]))) ++i;
      if (i > w) words.push_back(content.substr(w, i - w));
    }
    if (!words.empty()) handle(words, LineContext{&file, line});
    start = end + 1;
  }
}

}  // namespace skinlab::geometry

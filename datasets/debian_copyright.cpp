#include "datasets/debian_copyright.hpp"

#include <fstream>
#include <sstream>
#include <vector>

#include "framework/core/error.hpp"

namespace skinlab::datasets {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::string> split_ws(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

/// DEP-5 licence short names to SPDX where they differ ("GPL-2+" → "GPL-2.0-or-later").
std::string spdx(const std::string& name) {
  if (name == "GPL-2+") return "GPL-2.0-or-later";
  if (name == "GPL-2") return "GPL-2.0-only";
  if (name == "GPL-3+") return "GPL-3.0-or-later";
  if (name == "public-domain") return "LicenseRef-public-domain";
  return name;
}

}  // namespace

bool dep5_match(const std::string& pattern, const std::string& path) {
  // Iterative wildcard match with backtracking to the last '*'.
  std::size_t p = 0, s = 0, star = std::string::npos, mark = 0;
  while (s < path.size()) {
    if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == path[s])) {
      ++p, ++s;
    } else if (p < pattern.size() && pattern[p] == '*') {
      star = p++, mark = s;
    } else if (star != std::string::npos) {
      p = star + 1, s = ++mark;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

CopyrightInfo debian_copyright(const std::filesystem::path& copyright_file,
                               const std::string& path) {
  std::ifstream in(copyright_file);
  if (!in) throw IoError(copyright_file.string() + ": cannot open the Debian copyright file");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);

  const bool dep5 = !lines.empty() && lines[0].rfind("Format:", 0) == 0;
  if (dep5) {
    CopyrightInfo found;
    bool matched = false;
    // Paragraphs are separated by blank lines; fields may continue on indented lines.
    for (std::size_t i = 0; i < lines.size();) {
      std::vector<std::string> files, holders;
      std::string licence;
      std::string field;
      for (; i < lines.size() && !trim(lines[i]).empty(); ++i) {
        const std::string& line = lines[i];
        const bool continuation = line[0] == ' ' || line[0] == '\t';
        std::string value = line;
        if (!continuation) {
          const auto colon = line.find(':');
          field = colon == std::string::npos ? "" : line.substr(0, colon);
          value = colon == std::string::npos ? "" : line.substr(colon + 1);
          if (field == "License") licence = trim(value);
        }
        if (field == "Files") {
          for (auto& w : split_ws(value)) files.push_back(w);
        } else if (field == "Copyright" && !trim(value).empty()) {
          holders.push_back(trim(value));
        }
      }
      for (; i < lines.size() && trim(lines[i]).empty(); ++i) {
      }
      for (const auto& pattern : files) {
        if (dep5_match(pattern, path)) {
          matched = true;
          found.licence = spdx(licence);
          found.attribution.clear();
          for (const auto& h : holders)
            found.attribution += (found.attribution.empty() ? "" : "; ") + h;
          break;
        }
      }
    }
    if (!matched) {
      throw IoError(copyright_file.string() + ": no Files: paragraph matches '" + path + "'");
    }
    return found;
  }

  // Free-form: the GPL notice and the "... ©"/"Copyright" line.
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  std::string flat;
  for (const auto& w : split_ws(text)) flat += w + " ";
  CopyrightInfo info;
  if (flat.find("GNU General Public License") != std::string::npos) {
    const bool later = flat.find("or (at your option) any later version") != std::string::npos;
    if (flat.find("version 2") != std::string::npos) {
      info.licence = later ? "GPL-2.0-or-later" : "GPL-2.0-only";
    } else if (flat.find("version 3") != std::string::npos) {
      info.licence = later ? "GPL-3.0-or-later" : "GPL-3.0-only";
    }
  }
  for (const auto& l : lines) {
    if (l.find("\u00a9") != std::string::npos || l.find("Copyright") == 0) {
      info.attribution = trim(l);
      break;
    }
  }
  if (info.licence.empty()) {
    throw IoError(copyright_file.string() +
                  ": free-form copyright file with no recognised licence");
  }
  return info;
}

}  // namespace skinlab::datasets

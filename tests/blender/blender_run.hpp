#pragma once
// Blender headless for the `long` tests of tests/blender: whether it is installed, running a
// script with arguments, and the "KEY value" lines the scripts print.

#include <cstdio>
#include <cstdlib>
#include <string>

namespace skinlab::testing {

/// Debian's blender package (3.4 on bookworm; its glTF importer needs python3-numpy).
inline bool blender_installed() { return std::system("command -v blender > /dev/null 2>&1") == 0; }

struct BlenderRun {
  int status;        ///< pclose status: 0 when Blender and the script succeeded
  std::string text;  ///< stdout and stderr, after a leading "\n" (for value_of)
};

/// `env blender -b --factory-startup --python-exit-code 1 --python script -- args`; `env` is
/// prepended to the command as it is (e.g. "BLENDER_USER_SCRIPTS='/tmp/x' ").
inline BlenderRun run_blender(const std::string& script, const std::string& args,
                              const std::string& env = "") {
  const std::string command = env + "blender -b --factory-startup --python-exit-code 1 --python '" +
                              script + "' -- " + args + " 2>&1";
  BlenderRun result{-1, "\n"};
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) result.text += buffer;
  result.status = ::pclose(pipe);
  return result;
}

/// The rest of the first line "KEY ..." of `text` (a run's text, which starts with "\n"); empty
/// when there is none.
inline std::string value_of(const std::string& text, const std::string& key) {
  const auto at = text.find("\n" + key + " ");
  if (at == std::string::npos) return "";
  const auto start = at + key.size() + 2;
  return text.substr(start, text.find('\n', start) - start);
}

}  // namespace skinlab::testing

#pragma once
// Runs the `skinlab` binary (or `skinlab-predict`) from the source directory, as a user runs it, and captures its exit
// status, stdout and stderr (for the CLI tests).

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "framework/core/atomic_file.hpp"
#include "tests/test_util.hpp"

namespace skinlab::testing {

struct Result {
  int status;
  std::string out;
  std::string err;
};

/// `command` through the shell, stdout and stderr captured apart.
inline Result run_shell(const std::string& command) {
  TempDir dir;
  const auto err_file = dir / "stderr.txt";
  const std::string redirected = "(" + command + ") 2>'" + err_file.string() + "'";
  FILE* pipe = ::popen(redirected.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("popen failed");
  std::string out;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) out += buffer.data();
  const int status = ::pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out, read_file(err_file)};
}

/// Runs `binary` with `args` from the source directory, as a user runs it.
inline Result run_program(const std::string& binary, const std::string& args) {
  return run_shell(std::string("cd '") + SKINLAB_SOURCE_DIR + "' && '" + binary + "' " + args);
}

/// Runs `skinlab` with `args`.
inline Result run(const std::string& args) { return run_program(SKINLAB_CLI, args); }

}  // namespace skinlab::testing

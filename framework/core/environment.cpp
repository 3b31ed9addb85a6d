#include "framework/core/environment.hpp"

#include <CGAL/version.h>
#include <H5public.h>
#include <malloc.h>
#include <fmt/core.h>
#include <spdlog/version.h>
#include <unistd.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <climits>
#include <ctime>
#include <fstream>
#include <utility>

#include "framework/core/error.hpp"

#ifndef SKINLAB_SOURCE_DIR
#error "SKINLAB_SOURCE_DIR must be defined by the build"
#endif
#if !defined(SKINLAB_BINARY_DIR) || !defined(SKINLAB_DATA_FROM_BIN)
#error "SKINLAB_BINARY_DIR and SKINLAB_DATA_FROM_BIN must be defined by the build"
#endif
#ifndef SKINLAB_BUILD_TYPE
#define SKINLAB_BUILD_TYPE "unknown"
#endif

namespace skinlab {

namespace {

ComputeRuntime& compute_runtime() {
  static ComputeRuntime runtime;
  return runtime;
}

/// The file a shared library with this soname was really loaded from (symlinks and Debian's
/// update-alternatives resolved), read from /proc/self/maps; "not loaded" when absent. The BLAS
/// behind libtorch is chosen at run time by alternatives (reference BLAS or OpenBLAS), and it
/// changes both speed (25x on a 5000x256x256 product) and the last bits of results.
std::string loaded_library(const std::string& soname) {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line)) {
    const auto slash = line.find('/');
    if (slash == std::string::npos) continue;
    const std::filesystem::path path = line.substr(slash);
    if (path.filename() != soname) continue;
    std::error_code ec;
    const auto real = std::filesystem::canonical(path, ec);
    return ec ? path.string() : real.string();
  }
  return "not loaded";
}

}  // namespace

std::filesystem::path source_dir() { return SKINLAB_SOURCE_DIR; }

std::filesystem::path executable_path() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe;
}

bool running_from_build_tree() {
  std::error_code ec;
  const std::filesystem::path build = std::filesystem::canonical(SKINLAB_BINARY_DIR, ec);
  if (ec) return false;
  const std::filesystem::path exe = executable_path();
  const auto [end, unused] = std::mismatch(build.begin(), build.end(), exe.begin(), exe.end());
  return end == build.end();
}

std::filesystem::path installed_data_dir() {
  const std::filesystem::path exe = executable_path();
  if (exe.empty()) return {};
  return (exe.parent_path() / SKINLAB_DATA_FROM_BIN / "skinlab").lexically_normal();
}

nlohmann::json git_json(const GitState& state) {
  nlohmann::json out = {{"git_commit", state.commit}, {"git_dirty", state.dirty}};
  if (state.dirty) {
    out["git_modified"] = state.modified;
    out["git_diff_sha256"] = state.diff_sha256;
  }
  return out;
}

void register_compute_runtime(ComputeRuntime runtime) { compute_runtime() = std::move(runtime); }

nlohmann::json library_versions() {
  nlohmann::json versions = {
      {"compiler", "g++ " __VERSION__},
      {"eigen", fmt::format("{}.{}.{}", EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION,
                            EIGEN_MINOR_VERSION)},
      {"cgal", CGAL_VERSION_STR},
      {"hdf5", fmt::format("{}.{}.{}", H5_VERS_MAJOR, H5_VERS_MINOR, H5_VERS_RELEASE)},
      {"fmt", fmt::format("{}.{}.{}", FMT_VERSION / 10000, FMT_VERSION / 100 % 100,
                          FMT_VERSION % 100)},
      {"spdlog", fmt::format("{}.{}.{}", SPDLOG_VER_MAJOR, SPDLOG_VER_MINOR, SPDLOG_VER_PATCH)},
      {"nlohmann_json", fmt::format("{}.{}.{}", NLOHMANN_JSON_VERSION_MAJOR,
                                    NLOHMANN_JSON_VERSION_MINOR, NLOHMANN_JSON_VERSION_PATCH)},
      {"blas", loaded_library("libblas.so.3")},
  };
  if (!compute_runtime().name.empty()) versions[compute_runtime().name] = compute_runtime().version;
  return versions;
}

void keep_freed_memory() {
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
}

double peak_memory_mib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // "… kB"
  }
  return 0.0;
}

std::string utc_time_text() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  ::gmtime_r(&now, &utc);
  std::array<char, 32> text{};
  std::strftime(text.data(), text.size(), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text.data();
}

nlohmann::json collect_environment(std::uint64_t seed, const std::vector<std::string>& command) {
  std::array<char, 256> host{};
  if (::gethostname(host.data(), host.size() - 1) != 0) host[0] = '\0';
  nlohmann::json env = git_json(build_git_state());
  env.update({
      {"build_type", SKINLAB_BUILD_TYPE},
      {"libraries", library_versions()},
      {"threads", compute_runtime().threads ? compute_runtime().threads() : 1},
      {"hardware_threads", static_cast<int>(::sysconf(_SC_NPROCESSORS_ONLN))},
      {"seed", seed},
      {"host", host.data()},
      {"time_utc", utc_time_text()},
      {"command", command},
  });
  return env;
}

}  // namespace skinlab

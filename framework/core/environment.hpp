#pragma once
/// \file
/// What a run records about the machine and the code it ran on (`env.json`), and what
/// `skinlab info` prints.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace skinlab {

/// Commit of a git work tree and whether tracked files differ from it.
struct GitState {
  std::string commit = "unknown";  ///< full SHA, or "unknown" outside a work tree / without git
  bool dirty = false;              ///< tracked files modified (untracked files do not count)
  std::vector<std::string> modified;  ///< those files (`git diff HEAD --name-only`), if dirty
  std::string diff_sha256;         ///< SHA-256 of `git diff HEAD --binary`, if dirty
};

/// The git state of the source tree this binary was compiled from, recorded at build time
/// (cmake/build_info.cmake). What env.json, the dataset file and `skinlab info` report: a binary
/// kept running while the tree moves on (a long sweep, a copied binary) still names its own
/// code, and a dirty build is identifiable by its modified files and diff hash.
const GitState& build_git_state();

/// {"git_commit", "git_dirty", "git_modified", "git_diff_sha256"} of `state` (the last two only
/// when dirty), as env.json records them.
nlohmann::json git_json(const GitState& state);

/// Versions of the compiler and of every library that can change a result:
/// {"compiler", <the compute runtime, e.g. "libtorch">, "eigen", "cgal", "hdf5", "yaml_cpp", "fmt", "spdlog", "json"}, and the
/// file the BLAS libtorch calls was loaded from ("blas").
nlohmann::json library_versions();

/// Makes glibc keep freed memory for reuse instead of returning it to the kernel: no mmap for
/// large blocks, no trimming of the heap top. libtorch allocates and frees the same large
/// tensor sizes again and again (every training step, every layer of a prediction), and with
/// glibc's defaults each of them came back as fresh zeroed pages (measured ~120 ms per 32 MB
/// on this VM; a 5K-vertex prediction takes 580 ms with the defaults, 400 ms without that).
/// Peak memory is unchanged, since the same sizes come back. Call once, first thing in main.
void keep_freed_memory();

/// This process's peak resident memory in MiB: VmHWM of /proc/self/status, the high-water mark
/// of the current address space. Unlike getrusage's ru_maxrss it does not count the parent's
/// pages a forked child held before exec. 0 where /proc is not available.
double peak_memory_mib();

/// The tensor library the numerical layers run on (libtorch, registered at start-up by
/// framework/tensors/threads.cpp): its name and version for library_versions(), and how to read
/// its intra-op thread count for the env.json record. The core layer does not depend on it.
struct ComputeRuntime {
  std::string name;              ///< key in library_versions(), e.g. "libtorch"
  std::string version;           ///< its version string
  int (*threads)() = nullptr;    ///< its intra-op thread count
};

/// Registers the compute runtime (a static registrar of the layer that owns it). The last call
/// wins; without one, library_versions() lists none and collect_environment() records 1 thread.
void register_compute_runtime(ComputeRuntime runtime);

/// The current time, UTC, ISO 8601 to the second ("2026-12-03T17:02:15Z"), as env.json records it.
std::string utc_time_text();

/// The `env.json` record of a run: git commit and dirty flag of the source tree, compiler,
/// library versions, build type, thread count, seed, host name, time (UTC, ISO 8601) and the
/// command line.
nlohmann::json collect_environment(std::uint64_t seed, const std::vector<std::string>& command);

/// The source tree this binary was built from. Only a program of that tree's own build directory
/// (running_from_build_tree) may read files from it: an installed program must not.
std::filesystem::path source_dir();

/// The running program's own file (/proc/self/exe, symbolic links resolved); empty when it
/// cannot be read.
std::filesystem::path executable_path();

/// Whether the running program lies inside the build directory it was compiled in (build/skinlab,
/// the test and benchmark programs), so that the source tree beside it is the one it was built
/// from. False for a program installed (`cmake --install`) or copied elsewhere.
bool running_from_build_tree();

/// `<directory of the program>/<bin-to-data>/skinlab`: where `cmake --install` puts skinlab's
/// data, relative to the installed program (`<prefix>/bin/skinlab` → `<prefix>/share/skinlab`
/// with the default GNUInstallDirs), so an installed prefix can be moved as a whole.
std::filesystem::path installed_data_dir();

}  // namespace skinlab

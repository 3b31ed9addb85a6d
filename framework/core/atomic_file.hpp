#pragma once
/// \file
/// Crash-safe file output: write under a temporary name in the target's directory, flush to
/// disk, then rename over the target. A crash or an exception at any point leaves either the old
/// file or the new one under the target name, never a half-written file.

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace skinlab {

/// A temporary path next to `target` that becomes `target` on `commit()`. Any writer can
/// produce the file (an ofstream, HDF5, libtorch's serializer). If the object is destroyed
/// without `commit()`, the temporary file is removed and `target` is untouched.
class AtomicPath {
 public:
  explicit AtomicPath(std::filesystem::path target);
  AtomicPath(const AtomicPath&) = delete;
  AtomicPath& operator=(const AtomicPath&) = delete;
  ~AtomicPath();

  /// Where to write: `<dir>/.<name>.tmp-<pid>-<n>`.
  const std::filesystem::path& temp() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }

  /// Flushes the temporary file to disk and renames it over `target` (and syncs the
  /// directory). Throws IoError naming the target if the temporary file is missing or the rename
  /// fails.
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool committed_ = false;
};

/// Writes `contents` to `target` atomically. Throws IoError naming `target` on failure.
void write_file_atomic(const std::filesystem::path& target, std::string_view contents);

/// Builds the directory `target` whole: `write` fills a staging directory `<target>.partial`
/// (created empty, replacing any left-over one), which is renamed to `target` when `write`
/// returns. If `write` throws, the staging directory is removed and `target` is untouched.
/// `target` must not exist, or be an empty directory (the caller checks which it allows).
void write_directory_atomic(const std::filesystem::path& target,
                            const std::function<void(const std::filesystem::path& staging)>& write);

/// Reads a whole file. Throws IoError naming `path` on failure.
std::string read_file(const std::filesystem::path& path);

}  // namespace skinlab

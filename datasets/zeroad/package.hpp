#pragma once
/// \file
/// Read access to 0 A.D.'s game data, either the packed mod archive (`public.zip`, as Debian's
/// 0ad-data ships it under /usr/share/games/0ad/mods/public/) or a directory with the same
/// layout (`art/meshes/...`, `art/skeletons/...`), such as the bundled subset.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace skinlab::datasets::zeroad {

class Package {
 public:
  /// Opens `path`: a regular file is read as a zip archive (libzip), a directory as an extracted
  /// tree. Throws IoError naming the path when it is missing or not a readable archive.
  explicit Package(const std::filesystem::path& path);
  ~Package();
  Package(const Package&) = delete;
  Package& operator=(const Package&) = delete;

  /// Every file entry whose '/'-separated path starts with `prefix` and ends with `suffix`,
  /// sorted. Directory entries of the archive are skipped.
  std::vector<std::string> list(const std::string& prefix, const std::string& suffix = "") const;
  bool contains(const std::string& entry) const;
  /// The bytes of `entry`. Throws IoError naming the package and the entry when it is missing
  /// or cannot be read completely.
  std::string read(const std::string& entry) const;
  /// Human-readable name of the package (its path).
  const std::string& name() const { return name_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string name_;
};

}  // namespace skinlab::datasets::zeroad

#pragma once
/// \file
/// `folder`: every rigged character file under a directory, so a user can bring their own
/// characters (RigNet's released data, Mixamo exports, studio assets).
///
/// Files: whatever the Open Asset Importer reads with bones (extensions .fbx .gltf .glb .dae
/// .b3d .smd .x .md5mesh, case-insensitive; geometry::import_character), and `name.obj` with
/// `name_rig.txt` beside it (RigNet's mesh + rig text; geometry::read_obj_rig). Other files are
/// ignored; an `.obj` without its rig file, or any file that cannot be read or fails validation,
/// becomes an Excluded entry with the error message. Files are visited in sorted path order so
/// the character order does not depend on the file system.
///
/// A character's name is its path relative to `path` without the extension, with '/' replaced
/// by '.' (an HDF5 group name). FBX files that declare another up axis (ImportReport::source_up)
/// are rotated to Y up here, since SourceCharacter carries no up axis; the normalisation of
/// preprocessing then only scales and translates.

#include <string>
#include <vector>

#include "framework/data/source.hpp"
#include "framework/core/config.hpp"

namespace skinlab::datasets {

class Folder final : public DatasetBuilder {
 public:
  struct Options {
    std::string path;         ///< directory to scan (required)
    std::string licence;      ///< SPDX-style licence of every file, e.g. "CC-BY-SA-3.0"
    std::string attribution;  ///< authors, for the dataset card
    /// Skeleton family of every character; empty: the file's stem (each file its own family).
    std::string skeleton;
    bool recursive = false;  ///< also scan sub-directories
    static Options from(const config::Node& node);
  };

  explicit Folder(Options options) : options_(std::move(options)) {}

  /// Throws IoError if `path` is not a readable directory; per-file problems go to `excluded`.
  std::vector<SourceCharacter> read(std::vector<Excluded>& excluded) const override;

  const Options& options() const { return options_; }

 private:
  Options options_;
};

}  // namespace skinlab::datasets

#pragma once
/// \file
/// `nexuiz`: the player characters of Nexuiz (Debian package nexuiz-data, GPL-2+): ZYM files
/// (datasets/nexuiz/zym.hpp) under `models/player/` inside `data.pk3` (a zip; pk3.hpp), or in a
/// directory holding the same tree extracted.
///
/// - Candidates: every `.zym` whose path starts with `include` (default "models/player/"); any
///   other `.zym` (weapons, vehicles, props) is excluded with that reason. Level-of-detail copies
///   `<name>_lod1/_lod2.zym` (the same character with fewer vertices and the same skeleton) are
///   excluded as such unless `lods` is true.
/// - Unweighted root subtrees are pruned (datasets/rigged_model.hpp). Weights are rigid (one bone
///   per vertex; see zym.hpp), which the shared cleaning reports.
/// - Animations: one per scene, frames = the scene's poses as global bone transforms; the bind
///   pose is pose 0 (as in DarkPlaces).
/// - Name: the path without "models/" and ".zym", '/' replaced by '.' (an HDF5 name:
///   "player.marine"); SourceCharacter::up = +Z (Quake frame); skeleton family: the
///   character ("marine": every Nexuiz player has its own skeleton, 38–75 bones).
/// - Licence and attribution from the package's (free-form) copyright file.

#include <string>

#include "framework/data/source.hpp"
#include "framework/core/config.hpp"

namespace skinlab::datasets {

class NexuizBuilder final : public DatasetBuilder {
 public:
  struct Options {
    std::string path = "/usr/share/games/nexuiz/data/data.pk3";  ///< a .pk3 or a directory
    std::string copyright = "/usr/share/doc/nexuiz-data/copyright";
    std::string include = "models/player/";
    bool lods = false;
    static Options from(const config::Node& node);
  };
  explicit NexuizBuilder(Options options) : options_(std::move(options)) {}

  /// Throws IoError if `path` is neither a readable zip archive nor a directory.
  std::vector<SourceCharacter> read(std::vector<Excluded>& excluded) const override;

 private:
  Options options_;
};

}  // namespace skinlab::datasets

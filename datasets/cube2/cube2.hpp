#pragma once
/// \file
/// `cube2`: the player characters of Cube 2/Sauerbraten (Debian package cube2-data, models under
/// CC-BY-3.0): IQM files (datasets/cube2/iqm.hpp) under the package's model directory, each
/// model with the animation clips stored as mesh-less IQM files next to it.
///
/// - Every `.iqm` with geometry is a candidate; one under a directory named in `exclude_dirs`
///   (by default Sauerbraten's first-person guns and hands `hudguns/`, third-person weapons
///   `vwep/` and `projectiles/`) is not a character and is excluded with that reason, as is one
///   without joints or blend weights, or one whose weighted joints do not form one tree.
/// - Unweighted root subtrees (IK and control rigs) are pruned (datasets/rigged_model.hpp).
/// - Animations: every clip of every mesh-less `.iqm` in the model's directory whose pose
///   hierarchy equals the model's joint hierarchy (same count, same parents). Frames are global
///   joint transforms in the model's frame; fps as stored.
/// - Character name: the path relative to `path` without `.iqm`, '/' replaced by '.' (an HDF5
///   name; e.g. "snoutx10k.snoutx10k"); skeleton family: its first directory ("snoutx10k");
///   frame and units as in the file, with SourceCharacter::up = +Z (IQM is Z up).
/// - Licence and attribution: the Debian copyright file's paragraph for
///   `copyright_prefix + <relative path>` (debian_copyright.hpp).

#include <string>
#include <vector>

#include "framework/data/source.hpp"
#include "framework/core/config.hpp"

namespace skinlab::datasets {

class Cube2Builder final : public DatasetBuilder {
 public:
  struct Options {
    std::string path = "/usr/share/games/cube2/packages/models";  ///< cube2-data's models
    std::string copyright = "/usr/share/doc/cube2-data/copyright";
    std::string copyright_prefix = "packages/models/";  ///< `path` inside the source tree
    std::vector<std::string> exclude_dirs = {"hudguns", "vwep", "projectiles"};
    static Options from(const config::Node& node);
  };
  explicit Cube2Builder(Options options) : options_(std::move(options)) {}

  /// Throws IoError if `path` is not a directory or the copyright file cannot be read.
  std::vector<SourceCharacter> read(std::vector<Excluded>& excluded) const override;

 private:
  Options options_;
};

}  // namespace skinlab::datasets

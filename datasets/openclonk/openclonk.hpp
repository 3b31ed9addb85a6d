#pragma once
/// \file
/// `openclonk`: the characters of OpenClonk (Debian package openclonk-data; game content
/// CC-BY 3.0): OGRE binary `.mesh` + `.skeleton` files (datasets/ogre/ogre_file.hpp) packed in
/// the game's C4Group archives (datasets/openclonk/c4group.hpp), turned into characters by the
/// `ogre` builder's rules (ogre::read_tree in datasets/ogre/ogre.hpp: exclusions, skeleton
/// look-up, OGRE's weights, joints, clips).
///
/// - `path`: the game's data directory (default /usr/share/games/openclonk, where Debian
///   installs the packed groups Objects.ocd, Decoration.ocd, Arena.ocf, …), or one packed group
///   file. Every packed group file in the directory (sorted by name) is inflated and listed
///   recursively; a group installed unpacked as a directory (Debian's Music.ocg) is read as a
///   directory. A group file that cannot be read is excluded, with its reason, under its name.
/// - A mesh's path is the group file's name and the path inside it, e.g.
///   `Objects.ocd/Animals.ocd/Wipf.ocd/Graphics.mesh`: what `exclude` and `credits` globs match
///   and the dataset card shows. Skeletons are looked up as `ogre` does (next to the mesh, in
///   the same definition, where OpenClonk's own loader finds them).
/// - Character name: "openclonk." + the groups of the path without their extensions + the
///   graphics name. OpenClonk loads a definition's `Graphics.mesh` as its graphics and
///   `Graphics<Name>.mesh` as its graphics set <Name>: `openclonk.Objects.Animals.Wipf`,
///   `openclonk.Objects.Clonk.Farmer`; a mesh of another name keeps its file name's stem.
/// - Source name "openclonk" (the dataset card, `splits.leave_out_sources`).
/// - The other options are the `ogre` builder's (ogre::TreeOptions): `exclude`, `licence`,
///   `attribution`, `credits`, `animations`, `max_animations_per_character`, `fps`,
///   `join_weighted_roots`, `max_unweighted_fraction`, `up` (+Y by default, which OpenClonk's
///   models use: the Clonk stands on y = 0, 20.8 units tall).

#include <string>

#include "datasets/ogre/ogre.hpp"
#include "framework/core/config.hpp"
#include "framework/data/source.hpp"

namespace skinlab::datasets {

class OpenClonkBuilder final : public DatasetBuilder {
 public:
  struct Options : ogre::TreeOptions {
    std::string path = "/usr/share/games/openclonk";  ///< the data directory or one group file
    static Options from(const config::Node& node);
  };

  explicit OpenClonkBuilder(Options options) : options_(std::move(options)) {}

  /// The character name of a mesh at `path` (see the file's header), e.g.
  /// "Objects.ocd/Clonk.ocd/GraphicsFarmer.mesh" → "openclonk.Objects.Clonk.Farmer".
  static std::string character_name(const std::string& path);

  /// Throws IoError when `path` is neither a directory nor a file (openclonk-data not
  /// installed); per-group and per-mesh problems go to `excluded`.
  std::vector<SourceCharacter> read(std::vector<Excluded>& excluded) const override;

 private:
  Options options_;
};

}  // namespace skinlab::datasets

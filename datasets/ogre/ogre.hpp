#pragma once
/// \file
/// `ogre`: skinned characters stored as OGRE binary `.mesh` files with their `.skeleton`
/// (datasets/ogre/ogre_file.hpp), e.g. Summoning Wars' and OpenDungeons' creatures.
///
/// Source location. With `repository: owner/name` the files are under
/// `$SKINLAB_DATA_DIR/<owner>/<name>/<path>` (a snapshot of that repository at `commit`,
/// which is recorded, not checked); without it `path` is a directory as given.
///
/// Every `.mesh` under that directory (recursively, sorted by path, extension
/// case-insensitive) is a candidate:
/// - one whose path relative to the directory matches a glob of `exclude` (fnmatch, `*`
///   crosses '/') is excluded with the reason given there (equipment and props that are not
///   characters);
/// - one without a SKELETON_LINK chunk is a static mesh (weapons, heads, hair attached to a
///   bone by the game) and is excluded with that reason;
/// - the linked skeleton is looked up as OGRE's resource groups find it: next to the mesh,
///   then case-insensitively next to the mesh, then by file name (case-insensitive) anywhere
///   under the directory, which must be unique. A missing or unreadable skeleton excludes the
///   mesh with the reason;
/// - weights are what OGRE's engine uses (Mesh::_rationaliseBoneAssignments): assignments to
///   the same bone are summed, a vertex with more than 4 keeps its 4 largest, and every vertex's
///   weights are divided by their sum. Stored weights are often not normalised: the builder
///   logs, per character, how many vertices it renormalised (|sum − 1| > 1e-3) and trimmed;
/// - vertices without bone assignment are dropped: unused ones always; ones that triangles use
///   (OGRE warns they "transform to wrong position when skeletal animation enabled": an
///   exporter's or artist's slip) together with those triangles, when they are at most
///   `max_unweighted_fraction` of the vertices, else the mesh is excluded;
/// - bones are reordered so that parents precede children (depth-first from the roots in
///   handle order) unless the file's order already does; unweighted root subtrees (IK targets,
///   floor markers) are pruned (datasets/rigged_model.hpp). When several root bones carry weight
///   (Blender rigs whose body parts hang from separate roots at one point) and
///   `join_weighted_roots` is set, a weightless joint `ogre_origin` at the model origin, with
///   the identity orientation, becomes their parent: it is the entity's scene node, which OGRE
///   makes the parent of every root bone. Without it such a mesh is excluded;
/// - joint positions are the bones' derived bind-pose positions (OGRE's Node composition, with
///   bone scale), in the mesh's model space and units; the up direction is `up` (+Y, OGRE's
///   convention, unless the game uses another: OpenDungeons is +Z up).
///
/// Character name: the relative path without `.mesh`, '/' replaced by '.'. Skeleton family:
/// the skeleton file's name without `.skeleton` (meshes sharing a skeleton share a family).
/// Licence and attribution: the first entry of `credits` whose glob matches the mesh's
/// relative path or its file name, else `licence` / `attribution`.
///
/// Animations (`animations: true`): the skeleton's clips in file order, sampled at `fps` from 0
/// to the clip length with OGRE's default interpolation (ogre::sample_animation), up to
/// `max_animations_per_character`. A clip that changes the derived scale of a kept joint
/// relative to the bind pose cannot be written as rigid transforms and is left out (logged;
/// the next clip takes its place).
///
/// Everything above but the directory listing is ogre::read_tree, which other builders reuse on
/// the files of an archive (datasets/openclonk/openclonk.hpp: OpenClonk's C4Group files).

#include <functional>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "datasets/repository.hpp"
#include "framework/data/source.hpp"

namespace skinlab::datasets {

namespace ogre {

/// How a tree of OGRE files becomes characters: the options shared by the `ogre` builder and
/// the builders that read OGRE files out of archives (the config keys of the same names).
struct TreeOptions {
  /// Licence and attribution of the files matching a glob (from the source's credits file).
  struct Credit {
    std::string files;        ///< glob on the relative path or file name, e.g. "Orc.*"
    std::string licence;      ///< SPDX-style
    std::string attribution;  ///< authors (and where the credit comes from)
  };
  std::string licence;      ///< SPDX-style licence of files no credit matches
  std::string attribution;  ///< authors of files no credit matches
  std::vector<Credit> credits;
  /// Glob on the relative path → reason: meshes that are not characters.
  std::vector<std::pair<std::string, std::string>> exclude;
  bool animations = true;
  int max_animations_per_character = 8;
  double fps = 24;
  /// Put several weighted root bones under an added weightless joint at the origin.
  bool join_weighted_roots = true;
  /// Largest share of vertices used by triangles but without bone assignment that is
  /// dropped (with their triangles) instead of excluding the mesh.
  double max_unweighted_fraction = 0.01;
  /// The up direction of the files' model space (SourceCharacter::up): OGRE's convention is
  /// +Y (Summoning Wars), but OpenDungeons models stand on z = 0 with +Z up.
  std::vector<double> up = {0, 1, 0};

  /// Reads the keys above through `f` (`credits` and `exclude` are sections of it) and checks
  /// them; `owner` names the builder in messages, e.g. "dataset 'ogre'".
  void read(config::Fields& f, const std::string& owner);
};

/// A file of a tree: its path relative to the tree's root ('/'-separated) and its bytes, read
/// on demand (from a directory, or out of an archive).
struct TreeFile {
  std::string path;
  std::function<std::string()> load;
};

/// A tree of files holding `.mesh` and `.skeleton` files (other files are ignored).
struct Tree {
  std::string source;  ///< SourceCharacter::source and Excluded::source of what is read
  std::string where;   ///< the tree's location, for messages (a directory, an archive)
  /// Every file, meshes in the order they become characters.
  std::vector<TreeFile> files;
  /// The character name of the mesh at a path; empty: the path without `.mesh`, '/' → '.'.
  std::function<std::string(const std::string&)> name;
};

/// The characters of every `.mesh` of `tree`, by the rules of this file's header (exclusions,
/// skeleton look-up, OGRE's weights, joints, clips); a mesh that fails goes to `excluded`
/// with its reason, named by its path in the tree.
std::vector<SourceCharacter> read_tree(const Tree& tree, const TreeOptions& options,
                                       std::vector<Excluded>& excluded);

}  // namespace ogre

class OgreBuilder final : public DatasetBuilder {
 public:
  using Credit = ogre::TreeOptions::Credit;
  struct Options : ogre::TreeOptions {
    /// Directory of the .mesh/.skeleton files: `path`, or `repository` + `commit` + `path`
    /// inside it (datasets/repository.hpp).
    RepositorySource source;
    static Options from(const config::Node& node);
  };

  explicit OgreBuilder(Options options) : options_(std::move(options)) {}

  /// The directory the files are read from (RepositorySource::root: IoError when a named
  /// repository is not in SKINLAB_DATA_DIR at its commit).
  std::filesystem::path root() const;

  /// Throws IoError if the directory cannot be read; per-file problems go to `excluded`.
  std::vector<SourceCharacter> read(std::vector<Excluded>& excluded) const override;

 private:
  Options options_;
};

}  // namespace skinlab::datasets

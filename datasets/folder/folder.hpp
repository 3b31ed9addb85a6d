#pragma once
/// \file
/// `folder`: every rigged character file under a directory, so a user can bring their own
/// characters (RigNet's released data, studio assets) and a config can name a public Git
/// repository of game assets at a fixed commit.
///
/// Files: whatever the Open Asset Importer reads with bones (extensions .fbx .gltf .glb .dae
/// .b3d .smd .x .md5mesh, case-insensitive; geometry::import_character), Inter-Quake Models
/// (.iqm, datasets/cube2/iqm.hpp; +Z up like every IQM), and `name.obj` with `name_rig.txt`
/// beside it (RigNet's mesh + rig text; geometry::read_obj_rig). Other files are ignored; an
/// `.obj` without its rig file, or any file that cannot be read or fails validation (a static
/// prop without bones among them), becomes an Excluded entry with the error message. Files are
/// visited in sorted path order so the character order does not depend on the file system.
///
/// Where the files are. Without `repository`, `path` is a directory (absolute, or relative to
/// the working directory). With `repository: owner/name` and `commit: <40 hex digits>`, the
/// files are those of that GitHub repository at that commit, which `scripts/fetch_data <config>`
/// checks out into `${SKINLAB_DATA_DIR}/<owner>/<name>/`; `path` is then a directory inside the
/// repository (default: its root). A missing SKINLAB_DATA_DIR or repository folder is an IoError
/// naming the variable, the repository and the folder and telling to run scripts/fetch_data;
/// when the folder is a Git checkout at another commit, that is an IoError too.
///
/// Which files. `include:` glob patterns select files by their path relative to `path`
/// (then sub-directories are scanned whatever `recursive` says); `exclude:` maps a relative
/// path or glob pattern to a reason, and every candidate file it matches becomes an Excluded
/// entry with that reason without being read (rigged props, duplicates, other licences), so
/// nothing is dropped silently. A pattern that matches no candidate file is a ConfigError (a
/// typo would otherwise keep a prop). Globs: `*` is any run of characters other than '/', `?`
/// one such character, `**` any run including '/' (`**/` also matches no directory), anchored
/// at `path` (as `/`-anchored .gitignore patterns, which scripts/fetch_data makes of them for
/// its sparse checkout); everything else is literal.
///
/// A character's name is `prefix` followed by its path relative to `path` without the
/// extension, '/' replaced by '.' (an HDF5 group name). Its skeleton family is `skeleton`:
/// `stem` (the default: each file its own family), `directory` (the name of the file's parent
/// directory, e.g. the asset pack), or any other string as the family of every character. The
/// dataset card lists the characters under the source `folder`, or under `owner/name` when a
/// repository is given.
///
/// Weights. Rows that do not sum to 1 (within 1e-3) are divided by their sum; each file with
/// such rows is logged with their count and the builder logs the total (import_character and
/// read_obj_rig would renormalise silently or reject the file). FBX files that declare another
/// up axis (ImportReport::source_up) are rotated to Y up here, since SourceCharacter carries no
/// up axis for assimp files; the normalisation of preprocessing then only scales and translates.
///
/// Bind pose and clips. Every assimp character gets SourceCharacter::bind, its joints'
/// bind-pose global transforms (geometry::ImportedMotion: B(bone) = G(mesh node) ·
/// mOffsetMatrix⁻¹, rigid once the hierarchy's uniform scale is divided out; IQM files get theirs
/// from their joints). With `animations: true` (default false, so existing configs build the
/// same files), an assimp file's skeletal clips become SourceCharacter::animations as `ogre`
/// reads OGRE's: in file order, sampled at `fps` (default 24) from 0 to the clip's duration, up
/// to `max_animations_per_character` (default 8) kept; frames[f][j] is joint j's node's animated
/// global transform, so that LBS with frames[f][j] · bind[j]⁻¹ is the skinning an assimp or glTF
/// viewer draws (geometry/import_character.hpp derives it). A clip that changes a joint's scale
/// relative to the bind pose (by more than 1e-4, relative) cannot be written as rigid transforms
/// and is left out; so is one that animates no joint (morph-target clips). A file whose bind
/// transforms are not rigid up to one uniform scale per joint (a mirror, a non-uniform scale) or
/// whose meshes bind a joint differently keeps its character without bind and clips. Each file's
/// kept and left-out clips are logged. Unweighted vertices rigidly attached to a joint through the
/// node hierarchy move with it from where the hierarchy places them, which is off the bind pose
/// when the file stores its nodes in another pose (ImportReport::max_rigid_misplacement, logged
/// as a warning). The rotation to Y up above applies to bind and frames too,
/// by conjugation (R·T·R⁻¹), so LBS stays exact in the rotated frame. IQM clips are not read here
/// (the `cube2` builder reads Cube 2's).

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "datasets/repository.hpp"
#include "framework/data/source.hpp"
#include "framework/core/config.hpp"

namespace skinlab::datasets {

class Folder final : public DatasetBuilder {
 public:
  struct Options {
    /// Where the files are (`path`, or `repository` + `commit` + `path` inside it; a missing
    /// `path` with a repository is its root). datasets/repository.hpp.
    RepositorySource source;
    std::string licence;      ///< SPDX-style licence of every file, e.g. "CC-BY-SA-3.0"
    std::string attribution;  ///< authors, for the dataset card
    /// Skeleton family: "stem" (or empty) for the file's stem, "directory" for its parent
    /// directory's name, anything else for that fixed family.
    std::string skeleton;
    std::string prefix;  ///< prepended to every character name, e.g. "kaykit."
    bool recursive = false;  ///< also scan sub-directories
    std::vector<std::string> include;  ///< glob patterns relative to `path`; empty: every file
    /// (pattern, reason) pairs in config order: matching files become Excluded with the reason.
    std::vector<std::pair<std::string, std::string>> exclude;
    /// Read the skeletal clips of assimp files (see the file comment). Off by default, unlike
    /// `ogre`'s, so that configs written before clips were read give the same dataset files.
    bool animations = false;
    int max_animations_per_character = 8;  ///< clips kept per character, in file order; ≥ 0
    double fps = 24;                       ///< sampling rate of the clips; > 0
    static Options from(const config::Node& node);
  };

  explicit Folder(Options options) : options_(std::move(options)) {}

  /// The directory scanned: `path`, or `${SKINLAB_DATA_DIR}/<owner>/<name>/<path>` with a
  /// repository. Throws IoError when SKINLAB_DATA_DIR is unset or the repository folder is
  /// missing or checked out at another commit (see the file comment).
  std::filesystem::path root() const;

  /// Throws IoError if the directory is not readable (see root()), ConfigError for an include
  /// or exclude pattern that matches no file; per-file problems go to `excluded`.
  std::vector<SourceCharacter> read(std::vector<Excluded>& excluded) const override;

  const Options& options() const { return options_; }

 private:
  Options options_;
};

/// Whether `path` (relative, '/'-separated) matches the glob `pattern` of the file comment.
bool glob_match(const std::string& pattern, const std::string& path);

}  // namespace skinlab::datasets

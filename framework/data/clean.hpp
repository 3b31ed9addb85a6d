#pragma once
/// \file
/// Cleaning of builder output before preprocessing, and the variant groups the
/// splits keep together (splits.hpp). Run by `skinlab prepare` between the builders and the
/// preprocessing; every decision is recorded so the dataset card can report it per character.
///
/// In order, over the characters of all sources:
/// 0. A character named in `exclude` (a map name → reason in the config: rigged props such as
///    a cart or a UI marker that pass the rules below but are not characters) is dropped with
///    that reason, and a character without weights is dropped ("no skin weights"). A name in
///    `exclude` that no source gives is an error (a typo would otherwise keep the prop).
///    When `skeletons` lists skeleton families, a character of any other family is dropped
///    ("skeleton family X is not in cleaning.skeletons"): a task that needs one shared skeleton,
///    such as DenseGATs' corrective deformation on the 0 A.D. bipeds, prepares only those.
/// 1. **Too few bones**: a character whose weights put a positive weight on fewer than
///    `min_bones` joints is dropped (RigNet's data filter keeps rigs with enough skinned joints;
///    a skinning network has nothing to learn on a 2-bone prop).
/// 2. **Rigid-only weights**: a character in which every vertex is bound to exactly one joint
///    (weight ≥ 1 − 1e-6 on one joint) is dropped when `drop_rigid` is set: such a rig (a
///    segmented, rigid-body model, e.g. every Nexuiz ZYM player model) has no blending to learn,
///    and its one-hot targets would teach hard boundaries.
/// 3. **Duplicates**: two characters with identical geometry — the same 64-bit FNV-1a hash of
///    their triangles, each as its corner positions quantised to `quantum` after normalisation
///    to 1 m height (geometry/normalize.hpp), sorted — keep
///    only the first in source order; the others are dropped as "duplicate geometry of <name>"
///    (0 A.D. horse breeds share one mesh under several names). The hash ignores the file's
///    units, placement, vertex and face order and vertices split at UV seams.
/// 4. **Variant groups**: characters that share a skeleton (same skeleton family and the same
///    joint names) and nearly the same mesh are put in one group, and splits never divide a
///    group. "Nearly the same mesh": of the cells (a grid of `group_cell` metres) the two
///    normalised surfaces occupy, a share of at least `group_similarity` has an occupied cell
///    of the other surface within one cell (26-neighbourhood; the tolerance makes the measure
///    indifferent to where the grid cuts a surface). Surfaces are sampled
///    on a barycentric lattice fine enough (spacing ≤ cell/2) that every cell a triangle crosses
///    gets a sample. Groups are the connected components of that relation (union–find), named
///    after their first member. Defaults, measured on the 0 A.D. characters: all 34 biped
///    garment variants are alike at coarse scales (overlap ≥ 0.95 at 1/64 m chains 27 of them
///    into one group, which would put every human on one side of a split), while at 1/128 m
///    (≈ 1.4 cm on a 1.8 m human) an armoured and a plain version of the same garment, or horse
///    breeds sharing a mesh, reach ≥ 0.99 and different garments stay below: 0.99 gives groups
///    of at most 5 characters.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "framework/data/source.hpp"
#include "framework/core/config.hpp"

namespace skinlab::data {

struct CleaningOptions {
  int min_bones = 4;               ///< joints with a positive weight, at least
  bool drop_rigid = true;          ///< drop characters whose every vertex has one joint
  double quantum = 1e-4;           ///< metres (1 m tall): position quantisation for duplicates
  double group_cell = 1.0 / 128;   ///< metres: cell of the surface-occupancy comparison
  double group_similarity = 0.99;  ///< surface overlap (rule 4) for one group; > 1: off
  std::map<std::string, std::string> exclude;  ///< character name → reason (rule 0)
  std::vector<std::string> skeletons;  ///< keep only these skeleton families; empty: all (rule 0)

  /// Decodes a `cleaning:` map (every field optional); errors name the file, line and key.
  static CleaningOptions from(const config::Node& node);
};

/// What cleaning decided for one character that was kept.
struct CleanedCharacter {
  datasets::SourceCharacter source;
  std::string group;  ///< name of the group's first member (itself when alone)
};

/// Applies the rules of the file comment. Dropped characters are appended to `excluded` with
/// their reason; the kept ones are returned in their original order. Throws Error for a name
/// in `options.exclude` that is not among `characters`.
std::vector<CleanedCharacter> clean(std::vector<datasets::SourceCharacter> characters,
                                    const CleaningOptions& options,
                                    std::vector<datasets::Excluded>& excluded);

/// The geometry hash of rule 3 (exposed for tests).
std::uint64_t geometry_hash(const geometry::Character& character, double quantum);

/// Overlap of the two normalised surfaces on a grid of `cell` metres, in [0, 1] (rule 4).
double surface_similarity(const geometry::Character& a, const geometry::Character& b, double cell);

}  // namespace skinlab::data

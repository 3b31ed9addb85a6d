#pragma once
/// \file
/// `zeroad`: characters of 0 A.D. (Wildfire Games; art CC-BY-SA 3.0), from Debian's 0ad-data
/// package (`public.zip`) or a directory with its layout (the bundled subset).
///
/// Every `art/meshes/skeletal/**.pmd` is one candidate character:
/// - mesh: the PMD's vertices and faces in the game's frame and units (read_pmd.hpp);
/// - skeleton: the standard skeleton matched to it (match_skeleton.hpp), joint j = PMD bone j,
///   at the bind-pose position of that bone. Standard skeletons may have several top-level
///   bones (IK helpers such as the biped's knee_L); our Skeleton has one root, so every extra
///   top-level bone is parented to the first one (documented choice; those helpers carry no
///   weight in the shipped meshes);
/// - weights: the PMD's up to 4 influences per vertex, per joint (#V×#J), checked to sum to 1;
/// - animations: the PSA clips of the actors (`art/actors/**.xml`, following variant files)
///   that use the mesh and have its bone count, as global joint transforms per frame with the
///   PMD bind pose (source.hpp's Animation), at 1000 / frame time fps;
/// - skeleton family: the standard skeleton's id (e.g. "Biped", "Horse").
///
/// Excluded, with the reason: meshes that do not parse (the parser's message), meshes without
/// bones (static props), meshes whose every vertex follows one bone (rigid props, e.g. the
/// placeholder triangle that only carries prop points for a flock), meshes no standard skeleton
/// matches, and characters failing validation. Skeleton and actor files that do not parse are
/// reported as excluded entries too (their path says which).

#include <string>

#include "framework/data/source.hpp"
#include "framework/core/config.hpp"

namespace skinlab::datasets {

class ZeroAdBuilder final : public DatasetBuilder {
 public:
  struct Options {
    /// The mod archive or a directory with its layout.
    std::string path = "/usr/share/games/0ad/mods/public/public.zip";
    bool animations = true;  ///< attach the actors' PSA clips
    /// At most this many clips per character (in actor order); 0 = all. A biped clip is
    /// ~46 joints × ~50 frames of transforms, and bipeds have hundreds of clips.
    int max_animations_per_character = 8;
    static Options from(const config::Node& node);
  };
  explicit ZeroAdBuilder(Options options) : options_(std::move(options)) {}
  std::vector<SourceCharacter> read(std::vector<Excluded>& excluded) const override;

 private:
  Options options_;
};

}  // namespace skinlab::datasets

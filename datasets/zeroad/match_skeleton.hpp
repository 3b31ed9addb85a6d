#pragma once
/// \file
/// Finds the standard skeleton a PMD mesh was converted against. A PMD names no skeleton, but
/// its bone count is its standard skeleton's bone count (PMDConvert.cpp writes one bone per
/// standard bone), so candidates are the standard skeletons with that count; identical trees
/// from several files count once. Each candidate tree is scored against the mesh's own data:
///
/// - **clip rigidity** (when PSA clips of that mesh's actors are given): a bone's offset in its
///   parent's frame, (G_parent⁻¹ G_child).translation, must stay what it is in the PMD's bind
///   pose in every frame; under a wrong tree, "parent" and "child" are unrelated bones and the
///   offset changes as they move independently. A joint is consistent when its largest change
///   over all frames is below `kRigidTolerance` × the mesh's bounding-box diagonal. Score: the
///   fraction of consistent weighted non-top-level joints (unweighted helpers such as prop and
///   IK bones are animated by translation in the shipped clips, so they are not evidence).
/// - **vertex proximity** (always): the median, over vertices, of the distance from the vertex
///   to the bones leaving its most-weighted joint (to each child; the joint itself at a leaf),
///   over the bounding-box diagonal. Weights belong to a bone's start joint, so under the right
///   tree a vertex lies near its joint's bones.
///
/// The best candidate is the one with the highest rigidity (ties, or no clips: the lowest
/// proximity). It is accepted when rigidity ≥ `kMinRigidFraction` (if clips were checked) and
/// proximity ≤ `kMaxProximity`; otherwise the mesh is unmatched with the measured values.

#include <string>
#include <vector>

#include "datasets/zeroad/read_pmd.hpp"
#include "datasets/zeroad/read_psa.hpp"
#include "datasets/zeroad/read_skeletons.hpp"

namespace skinlab::datasets::zeroad {

constexpr double kRigidTolerance = 0.01;
constexpr double kMinRigidFraction = 0.75;
constexpr double kMaxProximity = 0.15;

struct SkeletonMatch {
  int index = -1;              ///< into the `skeletons` argument; -1 when unmatched
  int candidates = 0;          ///< distinct trees with the PMD's bone count
  int clips_checked = 0;       ///< clips with the PMD's bone count that were scored
  double rigid_fraction = -1;  ///< of the chosen tree; -1 without clips
  double proximity = -1;       ///< of the chosen tree
  std::string reason;          ///< why unmatched; empty when matched
};

/// \param pmd        a mesh with at least one bone
/// \param skeletons  every standard skeleton of the package
/// \param clips      PSA clips the actors pair with this mesh (any bone count; others ignored)
SkeletonMatch match_skeleton(const Pmd& pmd, const std::vector<StandardSkeleton>& skeletons,
                             const std::vector<const Psa*>& clips);

}  // namespace skinlab::datasets::zeroad

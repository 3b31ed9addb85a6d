#pragma once
/// \file
/// Removing the weightless end joints of a rig: the other convention of where a skeleton ends.
///
/// Game skeletons often end in joints that skin nothing (0 A.D.'s "head_end", bone-tail markers
/// of Blender exports, IK targets), so the joint that carries the head's weight has a child and a
/// real bone. Joint-only rigs (glTF, RigNet's rig text) usually end at the weighted joint itself.
/// A model trained on one convention sees only one kind of leaf; training on both (preprocess's
/// `drop_weightless_leaves`) shows it leaf joints that carry weight and leaf joints that do not.

#include <functional>
#include <vector>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

/// Removes, repeatedly, every leaf joint j (never the root) for which `removable(j)` holds, j
/// an index of the skeleton as given: a chain of removable end joints goes whole, a removable
/// joint above a kept one stays. Joint order is kept, parents are re-indexed, leaf tips (if
/// set) are dropped with their joints, and the weights (if any) move onto the kept joints by
/// onto_kept_joints (a removed joint's weight to its nearest kept ancestor). Returns the
/// original indices of the joints kept, in order (every joint when nothing was removed).
std::vector<int> drop_leaves(Character& character, const std::function<bool(int)>& removable);

/// drop_leaves of every joint whose weight column is zero, until every leaf carries weight (or
/// only the root is left). Requires a validated character with weights. Returns the original
/// indices of the joints kept, to re-index per-joint data such as animation transforms.
std::vector<int> drop_weightless_leaves(Character& character);

/// Another set of weights of the same rig (#V×#J, the skeleton before the drop, whose `parents`
/// are given) on the joints `kept` that drop_weightless_leaves returned: column kept[i] becomes
/// column i, and the weight of a removed joint goes to its nearest kept ancestor, on whose bone
/// the removed joint lies. Row sums are unchanged. Used to score a method that weights end joints
/// the truth leaves empty (`skinlab score`) on the truth's bones.
SparseWeights onto_kept_joints(const SparseWeights& weights, const std::vector<int>& parents,
                               const std::vector<int>& kept);

}  // namespace skinlab::geometry

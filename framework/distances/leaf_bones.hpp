#pragma once
/// \file
/// Where the bone of a leaf joint ends: the paper's zero-length helper bone, or a bone with
/// extent into the leaf's own region of the mesh.
///
/// **The paper's construction** (HeterSkinNet Sec. 3.2, "we add a virtual bone for every leaf
/// joint for skinning at the end of limbs"; RigNet's virtual leaf bones) is a zero-length bone at
/// the leaf joint. That point is also the end of the parent's bone, so every vertex–bone distance
/// ties between the two (a point-to-segment distance is never smaller for a point than for a
/// segment that ends at it): under every distance the parent bone is at least as near as the leaf,
/// and a network sees two bones that differ only in their length. Where the artist weighted the
/// leaf (a head, a hand, a foot, a tail tip: skeletons saved joint-only, as glTF and RigNet's rig
/// text are), a network trained on skeletons that end in weightless end joints learns that the
/// parent wins.
///
/// **`extended`** gives a leaf joint a bone from the joint along its parent bone's direction to
/// where that ray leaves the mesh, at most `max_length` × the parent bone's length:
///
///     d   = (p_leaf − p_parent) / |p_leaf − p_parent|      (the nearest ancestor at another
///                                                           position if the parent coincides)
///     t*  = the nearest intersection of the ray p_leaf + t·d (t > 0) with the mesh surface
///     tip = p_leaf + min(t*, max_length · |p_leaf − p_parent|) · d
///
/// Why this construction: the region a leaf joint skins lies beyond the joint, continuing the
/// limb (the head above the neck joint, the hand past the wrist, the tail tip); the first surface
/// crossing along the limb's direction is the end of that region for a joint inside the mesh,
/// and the bound keeps a ray that runs along a thin part (or leaves through a far part of the
/// body) from producing a bone longer than the limb's own last segment. It uses only what every
/// rig has (joint positions and the mesh), so it is the same for a joint-only glTF, a rig text
/// and a game skeleton with bone tails. A leaf joint with no intersection ahead (a joint outside
/// the mesh pointing away from it, such as a weightless end marker) keeps a zero-length bone,
/// as does a leaf whose every ancestor sits at its position or the root of a one-joint skeleton.
/// The foot is its weak case: the ray along the shin meets the sole soon, so the foot's bone is
/// short; it still separates the foot from the end of the shin.
///
/// **Where the ray ends** (`ends_at`). `first_surface` (the default, every prepared dataset
/// before 2026-12-06): t* is the nearest crossing of any triangle. Game characters are often
/// several closed parts that overlap (a head pushed onto a body whose neck is capped), and then
/// the first surface ahead is the other part's cap, not the end of the leaf's region: on the
/// KayKit adventurers the head's bone ended 2.5-8.5 mm above the head joint (0.3-0.4 m of head
/// above it).
/// `enclosing_parts`: the ray ends where it leaves the last of the parts that enclose the leaf
/// joint. A part is a connected component of the mesh's triangles (shared vertex indices); it
/// encloses the joint when the ray crosses it an odd number of times (the parity test of a closed
/// surface); t* is the largest, over the enclosing parts, of the part's nearest crossing. Caps
/// and shells of parts that do not enclose the joint no longer stop the ray. When no part
/// encloses the joint (an open mesh, a joint outside), the nearest crossing is kept. Measured
/// with per-joint bone heat on every test set: results/tables/leaf_bones_enclosing_bone_heat.md.
///
/// **Roots that end a chain** (`roots: true`; off by default and in every dataset prepared
/// before 2026-12-07). A root with one child is the other end of a chain: a fish's first bone at
/// its head, a tail-first chain, a hip joint with the spine as its only child. The region beyond
/// it (the fish's head in front of the root) has no bone of its own: its nearest bone is the
/// root's bone to its child, which it meets at that bone's end point, as a vertex at the start of
/// any other bone meets it, where the weight usually belongs to the parent bone ending there.
/// With `roots`, such a root gets a helper bone by the same ray, from the root away from its
/// child (the first descendant on the chain at another position), bounded by `max_length` × the
/// root's bone; its tip is the root's row of Skeleton::leaf_tips (Skeleton::has_root_bone). The
/// root's weight is then split between its two bones by the preprocessing's rule for a joint
/// that starts several bones (the nearer one, data/preprocess.hpp), and both map back to the
/// root joint. A root with no surface ahead (outside the mesh, facing away, as 0 A.D.'s ground
/// roots) keeps only its bone to the child, so the skeleton is as before. `leaf_bias`
/// (models/branched_model.hpp) counts the root's helper bone as a leaf's: both end a chain.
/// Measured with the Quaternius packs left out of training (their fish have the root at the
/// head; results/tables/loso_quaternius_roots.md): a model trained with root bones skins the
/// fish worse than one trained without, so no model uses the option.
///
/// The result is Skeleton::leaf_tips; bones, their order and the bone-level targets do not
/// change (a leaf's weight is its helper bone's, data/preprocess.hpp) except for the root's
/// helper bone of `roots`, only the geometry that distances, binders and the bone attribute
/// (Sec. 3.2) see.

#include <Eigen/Core>
#include <string>

#include "framework/core/config.hpp"
#include "framework/geometry/mesh.hpp"
#include "framework/geometry/skeleton.hpp"

namespace skinlab::distances {

struct LeafBoneOptions {
  enum class Kind { kHelper, kExtended };
  Kind kind = Kind::kHelper;  ///< `helper` (the paper) or `extended` (this file's comment)
  double max_length = 1.0;    ///< bound of an extended bone, × the parent bone's length; > 0
  enum class End { kFirstSurface, kEnclosingParts };
  End ends_at = End::kFirstSurface;  ///< where the ray ends (this file's comment)
  bool roots = false;  ///< a helper bone for a root with one child (this file's comment)

  /// Decodes `leaf_bones: helper` / `leaf_bones: extended` or the map
  /// `{type: extended, max_length: 1.0, ends_at: enclosing_parts, roots: true}`; errors name
  /// the config file, line and key.
  static LeafBoneOptions from(const config::Node& node);
  /// "helper" or "extended".
  std::string name() const;
};

/// #J×3 leaf tips of `skeleton` on `mesh` (the `extended` construction above): row j is the tip
/// of leaf joint j, and the joint's own position for every joint with children, except with
/// `roots` the root's tip when it has one child and a surface ahead. Both in the same frame and
/// units. Throws GeometryError (prefixed by `source`) for an invalid mesh or skeleton or
/// `max_length` ≤ 0.
Eigen::MatrixXd extended_leaf_tips(
    const geometry::Mesh& mesh, const geometry::Skeleton& skeleton, double max_length,
    const std::string& source,
    LeafBoneOptions::End ends_at = LeafBoneOptions::End::kFirstSurface, bool roots = false);

/// Sets `skeleton.leaf_tips` as `options` asks: cleared for `helper`, extended_leaf_tips(...)
/// for `extended`.
void place_leaf_bones(const geometry::Mesh& mesh, geometry::Skeleton& skeleton,
                      const LeafBoneOptions& options, const std::string& source);

}  // namespace skinlab::distances

#pragma once
/// \file
/// `bone_heat`: Blender's "Automatic Weights" (armature parenting "With Automatic Weights"), the
/// bone heat diffusion of Baran & Popović, "Automatic Rigging and Animation of 3D Characters",
/// SIGGRAPH 2007, Sec. 4. For every bone i, with one factorisation shared by all bones:
///
///     (−Δ + H) w_i = H p_i
///
/// - Orientation (`orient_outward`, on by default): the faces of every connected part wound
///   inwards are flipped first (geometry/orient_outward.hpp); the normal-weighted distance and
///   the front-face visibility below assume outward normals.
/// - Δ: the cotangent Laplacian with vertex-area normalisation, assembled as Blender's
///   source/blender/editors/armature/meshlaplacian.cc does (`laplacian_triangle_area`,
///   `laplacian_triangle_weights`): edge weight t_jk = Σ over the triangles of edge jk of the
///   cotangent of the opposite angle divided by the number of triangles sharing the edge (Blender
///   divides by the face count "instead of *0.5", so a manifold edge gets ½(cot α + cot β) and a
///   boundary edge cot α); vertex area a_j = Blender's `varea`: per non-obtuse triangle
///   ¼ Σ cot·|edge|² over the two edges at j, per obtuse triangle the full area at the obtuse
///   corner and half of it at the others (twice the mixed Voronoi area of Meyer et al. 2003);
///   row j of −Δ is (0.5 / a_j) Σ_k t_jk (w_j − w_k): on a manifold mesh ¼ of the textbook
///   (1 / 2A_j) Σ_k (cot α + cot β)(w_j − w_k), so Blender's c = 1 is c = 4 with that Δ. We solve the equivalent symmetric system
///   (L + 2 diag(a) H) w_i = 2 diag(a) H p_i, L_jk = −t_jk, L_jj = Σ_k t_jk, with
///   Eigen::SimplicialLDLT (L is not an M-matrix with obtuse triangles, so LDLT, not LLT).
///   Triangles whose doubled area is ≤ 1e-10 × their longest squared edge (cotangent above
///   ~1e10) contribute nothing, as in geometry::laplacian, instead of Blender's float Inf.
/// - Distance of vertex j to bone i (`heat_source_distance`, `normal_weighted_distance: true`):
///   d = |x_j − c| / (½ (cos θ + 1.001)), c the closest point of the bone segment, cos θ between
///   the unit vector from c to x_j and the vertex normal (sum of the unit normals of its
///   triangles, normalised): a vertex facing away from the bone keeps ≈ its Euclidean distance,
///   one facing the bone is pushed up to 2000× farther. `false` gives Pinocchio's plain
///   Euclidean distance.
/// - Visibility (`heat_ray_source_visible`): bone i is visible from vertex j when the segment
///   from x_j to c, shortened by 1e-5 of its length at both ends, crosses no triangle from its
///   front side (Blender's `bvh_callback` counts a hit only when the unit triangle normal and the
///   unit ray direction have dot < −1e-5; crossing a triangle from behind, e.g. leaving the arm
///   on the way to the arm bone, does not block). CGAL AABB tree. A vertex in no triangle sees
///   every bone (Blender's `vltree[vertex] == nullptr`).
/// - Nearest bones (`closest`): `visible` (default, Baran & Popović's "nearest visible bone"):
///   d_j = the smallest d over the bones visible from j, and the closest bones are the visible
///   ones within d_j (1 + 1e-4) (Blender's DISTANCE_EPSILON). `blender`: Blender's
///   `heat_set_H`: d_j = the smallest d over all bones, and the closest bones are those within
///   d_j (1 + 1e-4) that are visible, so a vertex whose nearest bone is hidden gets H = 0 even if
///   another bone is visible.
/// - H and p (`heat_set_H`): with k closest bones, H_jj = k c / max(d_j, 1e-4)² and p_i(j) = 1/k
///   for each closest bone (so H p = c / d²), H_jj = 0 and p = 0 when k = 0. c = `heat_constant`
///   (Pinocchio and Blender's C_WEIGHT: 1). The 1e-4 floor is Blender's, in Blender units; our
///   characters are 1 m tall, Blender characters usually ~2 m, so it is kept in metres.
/// - Weight limit (`heat_limit_weight`): w < 0.025 → 0; 0.025 ≤ w < 0.05 → 0.05 (w − 0.025) /
///   0.025 (a ramp to 0.05 instead of a jump); otherwise w (negative solutions are thereby 0).
///   Blender stores these in vertex groups and normalises at deform time; we renormalise rows.
///   A row that the limit empties (only possible with > 20 bones sharing a vertex) keeps its
///   unlimited non-negative weights.
///
/// Heat sources (`heat_sources`). `bones` (default; the bones every other method reads): one
/// segment per parent–child pair, so a joint with several children (a chest with neck and
/// shoulders, a neck with head and ears) owns a segment to each of them, and the helper bones
/// at leaf joints (zero-length, or to the leaf's tip when the skeleton has leaf tips). `joints`:
/// one segment per joint, as Blender builds an armature from a joint-only skeleton (a glTF; its
/// importer's default "Temperance" bone heuristic): from the joint to its only child; with
/// several children toward the mean of their offsets, as long as the nearest child is far (the
/// heuristic takes the joint's local axis nearest that mean, which we do not have: joints carry
/// no orientation here); at a leaf, the helper bone. Each joint's heat then goes to the bone
/// starting at it nearest to the vertex. With `bones`, the segments from a branching joint to
/// its children run through the children's regions (the head and ears of a neck with three
/// children) and give them to the branching joint; Blender's bones start at each child.
///
/// Not reproduced: Blender's X-mirror option, B-Bone segments and selected-bones-only binding.
///
/// Where Blender leaves vertices without weight, the binder contract forbids zero rows. A
/// connected component (over non-degenerate triangles) none of whose vertices sees a closest
/// bone (H = 0 everywhere: a floating accessory hidden from every bone, a part outside the
/// skeleton behind the body) makes the system singular on it; Blender reports "failed to find
/// solution for one or more bones" or leaves it unweighted. Such components are taken out of the
/// system and each of their vertices gets weight 1 on the bone nearest to it by Euclidean
/// point–segment distance (ties: shared equally). A vertex in no non-degenerate triangle (area
/// 0) gets p if it sees a bone, else the same Euclidean fallback. Both are counted in
/// BoneHeatStats.
///
/// Complexity: visibility O(#V · #B log #F) segment queries in the worst case (bones are tried
/// nearest first), one sparse LDLT of size #V, #B back-substitutions.

#include <Eigen/Core>
#include <string>
#include <utility>

#include "framework/binders/binder.hpp"
#include "framework/core/config.hpp"

namespace skinlab::baselines {

/// What one `BoneHeat::bind` did, for tests and reports.
struct BoneHeatStats {
  int invisible_vertices = 0;   ///< vertices with H = 0 (no closest bone visible)
  int fallback_components = 0;  ///< components bound by the Euclidean fallback
  int fallback_vertices = 0;    ///< their vertices, plus zero-area vertices without a visible bone
  int limited_rows = 0;         ///< rows emptied by the weight limit (kept unlimited)
  int flipped_parts = 0;        ///< connected parts re-oriented outwards
};

class BoneHeat final : public binders::Binder {
 public:
  struct Options {
    double heat_constant = 1.0;           ///< c (Pinocchio; Blender C_WEIGHT), > 0
    std::string closest = "visible";      ///< "visible" or "blender" (see the file comment)
    /// "bones": one heat source per bone of Skeleton::bones() (a segment per parent–child pair,
    /// and the leaf helper bones); "joints": one per joint, as Blender's armature (see the file
    /// comment).
    std::string heat_sources = "bones";
    bool normal_weighted_distance = true;  ///< Blender's heat_source_distance; false: Euclidean
    /// Flip the faces of parts wound inwards first (geometry/orient_outward.hpp): the distance
    /// and the visibility test read front and back from the winding. Blender works with the
    /// normals it is given; the prepared game characters are all wound inwards.
    bool orient_outward = true;
    double weight_limit_start = 0.05;     ///< Blender WEIGHT_LIMIT_START
    double weight_limit_end = 0.025;      ///< Blender WEIGHT_LIMIT_END; 0 ≤ end < start ≤ 1
    static Options from(const config::Node& node);
  };

  explicit BoneHeat(Options options) : options_(std::move(options)) {}

  Eigen::MatrixXd bind(const geometry::Mesh& mesh,
                       const geometry::Skeleton& skeleton) const override {
    return bind(mesh, skeleton, nullptr);
  }
  /// As above; fills `stats` when it is not null.
  Eigen::MatrixXd bind(const geometry::Mesh& mesh, const geometry::Skeleton& skeleton,
                       BoneHeatStats* stats) const;

  const Options& options() const { return options_; }

 private:
  Options options_;
};

}  // namespace skinlab::baselines

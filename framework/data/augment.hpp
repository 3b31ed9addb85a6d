#pragma once
/// \file
/// Augmented training copies of a character, made by `skinlab prepare` (prepare.hpp) so that
/// every distance (HollowDist, Euclidean, volumetric geodesic) is computed exactly on the copy's
/// geometry: HollowDist, for one, is invariant neither to pose nor to anisotropic scale, so a
/// copy cannot be derived from its original's stored distances.
///
/// Config (`preprocess.augment`, every key optional; absent: off):
///
///     augment:
///       copies: 2        # copies per training character (0, the default: none)
///       seed: 0
///       pose: {clips: true, random_degrees: 25, random_fraction: 0.3}
///       scale: [0.8, 1.25]
///       mirror: 0.5
///
/// A copy is its original re-posed, then scaled, then mirrored, in the original's normalised
/// frame (after merging, subdivision and leaf-bone placement, preprocess.hpp):
///
/// - **pose**: with `clips: true` and a character with clips (0 A.D. PSA, glTF and Ogre
///   animations), one frame of one of its own clips (a clip, then a frame in it, uniformly), the
///   joints moving by frame(j) · bind(j)⁻¹; otherwise, with `random_degrees: σ`, a random pose of
///   geometry::random_pose (the deformation error's sampler: round(random_fraction · #J) joints
///   each turned about a uniform axis by an angle from N(0, σ²)) through forward_kinematics. The
///   mesh follows by linear blend skinning with the character's own artist weights; a joint moves
///   to T_j · p_j and a leaf's tip (extended leaf bones) to T_j · tip_j, so the tip follows its
///   leaf rather than being cast anew along the posed parent bone. A character with neither
///   (no clips, no `random_degrees`) keeps its bind pose.
/// - **scale**: x, y and z each scaled by a factor drawn log-uniformly in [min, max] (so s and
///   1/s are equally likely for a range symmetric in log).
/// - **mirror**: with probability p, x ↦ −x (a left–right reflection in the normalised frame)
///   and every face's winding reversed, so faces keep facing the side they faced (outward
///   stays outward); joint names are not swapped, so a "left" joint then lies on the right.
///
/// The weights, the joint order, the bones and the faces' vertices do not change (mirroring only
/// reverses each face's vertex order), and neither does the vertex map. The copy is then
/// normalised again to the dataset's frame (1 m tall, feet at y = 0, x/z centred), and the rest
/// of the preprocessing (distances, top-K, targets, graph edges, Laplacian) runs on it as on any
/// character. A copy has no clips (they were relative to the original's bind pose).
///
/// Each copy's draws come from keyed_engine(seed, "<copy name>/pose"), ".../scale" and
/// ".../mirror" (core/stable_random.hpp): a function of the config and the names only, the same
/// on every machine and in every thread order, and switching one kind on or off leaves the
/// others' draws as they were (an ablation's poses are the full configuration's).

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/data/source.hpp"
#include "framework/geometry/normalize.hpp"

namespace skinlab::data {

struct AugmentOptions {
  int copies = 0;                ///< per training character; 0: off
  std::int64_t seed = 0;         ///< combined with each copy's name
  bool pose = false;             ///< `pose:` given
  bool pose_clips = false;       ///< pose.clips: a frame of the character's own clips
  double random_degrees = -1;    ///< pose.random_degrees (σ); < 0: no random poses
  double random_fraction = 0.3;  ///< pose.random_fraction: share of the joints turned
  bool scale = false;            ///< `scale:` given
  double scale_min = 1, scale_max = 1;
  double mirror = 0;  ///< probability of a mirror, [0, 1]

  /// Decodes a `preprocess.augment` map; errors name the file, line and key.
  static AugmentOptions from(const config::Node& node);
};

/// What was drawn for one copy.
struct Augmentation {
  /// #J transforms relative to the bind pose, in the normalised frame; empty: the bind pose.
  std::vector<Eigen::Affine3d> pose;
  std::string pose_source;  ///< "clip '<name>' frame <f>", "random", or "" (bind pose)
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  bool mirror = false;
};

/// "<name>~aug<copy>", the name of copy `copy` (0-based) of character `name`.
std::string augmented_name(const std::string& name, int copy);

/// Draws copy `copy` of character `name` (the file comment's rules). `skeleton` is the
/// character's skeleton in the normalised frame; `clips` its clips in the source frame, with
/// `to_frame` the similarity from the source frame to the normalised frame (clips of another
/// joint count, or without frames, are not used).
Augmentation draw_augmentation(const AugmentOptions& options, const std::string& name, int copy,
                               const geometry::Skeleton& skeleton,
                               const std::vector<datasets::Animation>& clips,
                               const Eigen::Matrix4d& to_frame);

/// Applies `augmentation` in place: V by LBS with `weights` (#V×#J) to the pose, then the
/// scale, then the mirror (with the faces' winding reversed); joint positions and leaf tips
/// follow. Throws GeometryError if the weights are not #V×#J.
void apply_augmentation(const Augmentation& augmentation, const geometry::SparseWeights& weights,
                        geometry::Mesh& mesh, geometry::Skeleton& skeleton);

/// apply_augmentation, then normalisation to the dataset's frame (geometry/normalize.hpp, leaf
/// tips included). Returns the normalising similarity; an augmentation that changes nothing
/// (bind pose, unit scale, no mirror) leaves everything bit for bit as it was and returns the
/// identity. `name` prefixes errors.
geometry::Similarity augment(const Augmentation& augmentation,
                             const geometry::SparseWeights& weights, geometry::Mesh& mesh,
                             geometry::Skeleton& skeleton, const std::string& name);

}  // namespace skinlab::data

#pragma once
/// \file
/// Preprocessing of one character as HeterSkinNet (Pan et al. 2021) Sec. 4.1, plus everything a
/// network needs per character (Sec. 3.2–3.4), computed once and stored in the dataset file:
///
/// 0. with `right_handed`, read a left-handed character (0 A.D.'s game frame) as the right-handed
///    one it shows (source.hpp make_right_handed: mirrored front to back, clips included); with
///    probability `drop_weightless_leaves`, remove the character's weightless end joints
///    (geometry/weightless_leaves.hpp);
/// 1. normalise: Y up, 1 m tall, feet at y = 0, x/z centred (geometry/normalize.hpp); the
///    similarity is kept (PreparedCharacter::normalisation);
/// 2. merge vertices at the same position (geometry/merge_vertices.hpp); weights of merged
///    vertices are averaged (equal at seams, Sec. 4.1); the original → merged map is kept;
/// 3. subdivide meshes below `min_vertices` into [min_vertices, max_vertices] (1K–5K in the
///    paper; geometry/subdivide.hpp) with weights interpolated linearly, W' = S · W (rows still
///    sum to 1 because the rows of S do);
/// 3b. place the leaf joints' bones (`leaf_bones`: the paper's zero-length helpers, or bones
///    with extent, distances/leaf_bones.hpp), so every distance sees the same bone geometry;
/// 3c. only for an augmented copy (PreprocessMode::augment_copy): re-pose, scale and mirror the
///    mesh, joints and leaf tips and normalise again (augment.hpp);
/// 4. per distance type of the config: D (#V×#B), the top-K candidate bones per vertex (K = 3,
///    Sec. 3.2) with their distances, and bone-level targets over the K candidates;
/// 4b. per `priors` entry (not in the paper): the #V×#B weights of a `binder` plug-in (e.g.
///    bone heat, binders/binder.hpp) on the same mesh and bones, for models that start from a
///    classical method's weights (PreparedCharacter::priors);
/// 5. one-ring edges (Eq. 2, N_m), geodesic neighbour edges (radius 0.06, at most 10; N_g) and
///    the uniform Laplacian of the smoothing loss (Sec. 3.4, Eq. 6) as triplets.
///
/// Bone-level targets (RigNet's rule, Xu et al. 2020, gen_dataset.py): artist weights are per
/// joint; a bone (start → end) carries its start joint's weight. A joint with several bones
/// starting at it (a branching joint: spine → two shoulders and the neck) gives its whole weight
/// to the one of those bones nearest to the vertex under the same distance type (ties: lower bone
/// index); a leaf joint's only bone is its helper bone. This yields a #V×#B bone weight matrix
/// with rows summing to 1; targets(v, k) is its entry at topk_index(v, k), so a target row sums
/// to ≤ 1 (the weight on bones outside the K candidates is dropped, as the paper's network can
/// only predict the K candidates). Top-K and the choice of bone use D rounded to float32 as
/// stored, so both can be recomputed exactly from the file.

#include <memory>
#include <string>
#include <vector>

#include "framework/data/source.hpp"
#include "framework/core/config.hpp"
#include "framework/data/augment.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/distances/distance.hpp"
#include "framework/distances/leaf_bones.hpp"

namespace skinlab::data {

struct PreprocessOptions {
  double merge_tolerance = 0.0;   ///< metres after normalisation; 0: bit-identical positions
  int min_vertices = 1000;        ///< subdivide below this many vertices (Sec. 4.1: 1K)
  int max_vertices = 5000;        ///< never subdivide beyond this many (Sec. 4.1: 5K)
  int top_k = 3;                  ///< candidate bones per vertex (Sec. 3.2: K = 3)
  double geodesic_radius = 0.06;  ///< metres (Sec. 3.3)
  int geodesic_max_neighbours = 10;
  /// Where a leaf joint's bone ends (distances/leaf_bones.hpp): `helper`, the paper's
  /// zero-length bone (the default, so the paper's tables stay reproducible), or `extended`.
  distances::LeafBoneOptions leaf_bones;
  /// Probability in [0, 1] that a character's weightless end joints are removed before
  /// everything else (geometry/weightless_leaves.hpp), so that a dataset mixes skeletons whose
  /// leaves carry weight with skeletons whose leaves do not. Decided per character from its
  /// name and `drop_seed`, so a preparation is repeatable. Characters without weights (to
  /// predict for) are never changed. 0: off (the paper).
  double drop_weightless_leaves = 0.0;
  std::int64_t drop_seed = 0;
  /// Step 0: mirror left-handed characters (SourceCharacter::left_handed) front to back into
  /// the right-handed frame every glTF, OBJ or FBX a user has is in. false (the default) keeps
  /// the source's frame, as every dataset prepared before the option existed; right-handed
  /// characters are never changed.
  bool right_handed = false;
  /// Augmented training copies (augment.hpp; `copies: 0`, the default, is off). Made by
  /// `skinlab prepare` for the characters some split trains on (prepare.hpp).
  AugmentOptions augment;
  /// Step 4b: `binder` nodes ({type: <key>, ...}), each type at most once; empty (the default,
  /// the paper) computes none. Kept as nodes and created by `preprocess`, so reading a
  /// preparation does not need the binder plug-ins linked (skinlab-predict); `prepare` checks
  /// that every entry can be created before it starts.
  std::vector<config::Node> priors;

  /// Decodes a `preprocess:` map (every field optional); errors name the file, line and key.
  static PreprocessOptions from(const config::Node& node);
};

/// A distance plug-in with the registry key it is stored under.
struct NamedDistance {
  std::string type;
  std::shared_ptr<const distances::Distance> distance;
};

/// Top-K of every row of D (#V×#B): #V×K bone indices sorted by (distance, index) and the
/// distances, K = min(k, #B). Requires k ≥ 1.
void top_k_bones(const Eigen::MatrixXd& D, int k, RowMatrixXi& index, RowMatrixXf& distance);

/// #V×#B bone weights from #V×#J joint weights by the rule of the file comment, using D
/// (#V×#B) to choose among the bones starting at a joint.
Eigen::MatrixXd bone_weights(const geometry::SparseWeights& W, const geometry::Skeleton& skeleton,
                             const Eigen::MatrixXd& D);

/// What `preprocess` is asked to do beyond the dataset defaults, for `skinlab predict`.
struct PreprocessMode {
  /// false: a character without weights is prepared too (empty `weights`, zero `targets`), as a
  /// character to predict for; true: one without weights is an error (a training character).
  bool require_weights = true;
  bool laplacian = true;  ///< step 5's Laplacian (only the smoothing loss needs it)
  /// ≥ 0: prepare copy `augment_copy` of the character (step 3c, `options.augment`), named
  /// augmented_name(name, augment_copy), with `augmented_from` set and no clips; -1: the
  /// character itself.
  int augment_copy = -1;
};

/// Wall-clock seconds of the steps of one `preprocess` call.
struct PreprocessTimes {
  double normalise = 0;  ///< steps 1–3: normalise, merge, subdivide
  double distance = 0;   ///< steps 4 and 4b: distances, top-K, targets and priors
  double graph = 0;      ///< step 5: one-ring and geodesic edges, Laplacian
};

/// True when `drop_weightless_leaves` applies to the character `name` (a hash of the name and
/// `drop_seed` against the probability; the same answer on every machine).
bool drops_weightless_leaves(const PreprocessOptions& options, const std::string& name);

/// `options` without the priors other than `keep` (empty: without any). Throws ConfigError naming
/// the prior when `keep` is not among them, e.g. for a model that reads a prior its dataset was
/// not prepared with.
PreprocessOptions keep_prior(PreprocessOptions options, const std::string& keep);

/// Runs steps 0–5 on `source` (which must carry weights unless `mode.require_weights` is
/// false). Throws (GeometryError, IoError) with the character's name in the message when any
/// step fails. `times`, when given, receives the time of each step.
PreparedCharacter preprocess(const datasets::SourceCharacter& source,
                             const std::vector<NamedDistance>& distances,
                             const PreprocessOptions& options = {},
                             const PreprocessMode& mode = {}, PreprocessTimes* times = nullptr);

}  // namespace skinlab::data

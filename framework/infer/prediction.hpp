#pragma once
/// \file
/// One prediction without the network: what `skinlab predict` (libtorch) and the Eigen-only
/// `skinlab-predict` share around their forward passes, so both prepare a character, pick its
/// candidate bones and map the weights back with the same code:
///
/// 1. check the character can be predicted for (size, joints inside the mesh, bones with
///    length), and leave out the helper ends outside the mesh (IK pole targets, controllers);
/// 2. the training preprocessing on the fly (data/preprocess.hpp, HeterSkinNet Sec. 4.1:
///    normalise, merge, subdivide; the model's distance and its top-K candidate bones, Sec. 3.2;
///    one-ring and geodesic edges, Eq. 3), and a check that every candidate is at a finite
///    distance;
/// 3. the network's #V×K distribution over the candidates (the caller's forward pass);
/// 4. scattered to #V×#B bone weights, pruned at 0.25 of the row maximum (Sec. 4.5), and mapped
///    back to the input's own vertices and joints (infer/map_back.hpp).
///
/// Every vertex gets weights. The distances assign every vertex a finite distance to every
/// bone (HollowDist restarts its search for parts the first search does not reach, HeterSkinNet
/// Alg. 1; the other distances have their own rules), so every vertex has K candidates; a
/// vertex whose candidate distances are not finite is an error naming the vertex, never a
/// silent zero row.

#include <string>
#include <vector>

#include "framework/data/dataset_file.hpp"
#include "framework/data/preprocess.hpp"
#include "framework/geometry/skin_weights.hpp"

namespace skinlab::infer {

/// Wall-clock seconds of the stages of one prediction (the benchmark's and `--timings`' rows).
struct StageTimes {
  double load = 0;       ///< reading the input file(s) and validating them
  double normalise = 0;  ///< normalise, merge co-located vertices, subdivide
  double distance = 0;   ///< vertex–bone distances and top-K candidates
  double graph = 0;      ///< one-ring and geodesic edges
  double network = 0;    ///< network input, forward pass, scatter and pruning
  double map_back = 0;   ///< weights at the input's vertices and joints
  double export_ = 0;    ///< writing the output file(s)
  double total() const {
    return load + normalise + distance + graph + network + map_back + export_;
  }
};

struct PredictOptions {
  /// Weights below this fraction of their row's maximum are dropped and the row renormalised
  /// (HeterSkinNet Sec. 4.5's 0.25, the post-processing every compared method gets); 0 keeps
  /// the network's raw distribution.
  double prune = 0.25;
  /// The input's up direction, rotated to +Y by the normalisation (geometry/normalize.hpp).
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  /// Inputs with more vertices are refused: the network's memory grows linearly with #V (the
  /// paper's characters have 1K–5K vertices; predict_bench measures the peak at 5K).
  int max_vertices = 50000;
  /// A joint farther than this fraction of the mesh's bounding-box diagonal outside that box
  /// is outside the mesh. An end of the skeleton lying wholly outside (a leaf joint, or a chain
  /// of them) is a helper that skins nothing: an IK pole target or a controller, which
  /// Blender's glTF export writes as joints like any bone. It is left out of the prediction
  /// (weight 0), since its bone from the parent would otherwise compete for the parent's
  /// vertices. Any other joint outside, or more than half of the joints, is an error: the rig
  /// and the mesh do not belong together (other units or another frame).
  double max_joint_outside = 0.5;
};

/// Throws Error naming the character and the element when `character` cannot be predicted
/// for: more than `options.max_vertices` vertices, a joint outside the mesh that is not a
/// helper end, or more than half of the joints outside (see PredictOptions::max_joint_outside),
/// or a skeleton of two or more joints that all sit at one point (every bone has zero length,
/// so no bone has a direction to skin along). Mesh and skeleton validity (finite, in range,
/// acyclic, one root) are checked when they are loaded. Returns the helper ends outside the
/// mesh that a prediction leaves out (joint indices, ascending; usually none).
std::vector<int> check_predictable(const geometry::Character& character,
                                   const PredictOptions& options);

/// `character` without the joints `left_out` (check_predictable's helper ends; its weights, if
/// any, move onto the kept joints, geometry::drop_leaves), and the input index of each joint
/// kept. Both the prediction and the scoring of a prediction skin this skeleton.
std::vector<int> without_helper_ends(geometry::Character& character,
                                     const std::vector<int>& left_out);

/// A character prepared for the network (steps 1–2) and how its joints relate to the input's.
struct PreparedInput {
  data::PreparedCharacter prepared;  ///< without the helper ends left out
  std::vector<int> input_joints;     ///< the input's index of each prepared joint
  int num_input_joints = 0;
  std::vector<int> left_out;         ///< the input's helper ends outside the mesh (weight 0)
};

struct Prediction {
  data::PreparedCharacter prepared;      ///< normalised, merged, subdivided; weights if given
  data::RowMatrixXf candidates;          ///< #V×K network output over prepared.topk_index
                                         ///< (empty for a binder: finish_bone_weights)
  data::RowMatrixXf prepared_weights;    ///< #V×#B at the prepared vertices, pruned
  data::RowMatrixXf source_weights;      ///< #V_in×#B at the input's vertices, pruned
  /// #V_in×#J per-joint weights at the input's vertices and joints (a left-out joint's column
  /// is empty)
  geometry::SparseWeights joint_weights;
  std::vector<int> left_out_joints;      ///< PreparedInput::left_out
  std::vector<int> input_joints;         ///< PreparedInput::input_joints
  /// #V×#B ground-truth bone weights at the prepared vertices when the input carried weights
  /// (the bone-level rule of data/preprocess.hpp with the model's distance); 0×0 otherwise
  data::RowMatrixXf prepared_truth;
};

/// The preprocessing a model was trained with: its dataset's `preprocess:` options and the one
/// distance the model reads (`distance`, a registry key).
struct Preparation {
  data::PreprocessOptions preprocess;
  std::vector<data::NamedDistance> distances;  ///< the one the model reads
  const std::string& distance() const { return distances.front().type; }
};

/// Steps 1–2 of the file comment for `character` (its weights, if any, are ignored by the
/// prediction and kept in the result for comparison); helper ends outside the mesh are left
/// out with a warning naming them. `times`, if given, receives normalise, distance and graph.
/// Throws Error naming the character and the element.
PreparedInput prepare_to_predict(const geometry::Character& character,
                                 const Preparation& preparation, const PredictOptions& options,
                                 StageTimes* times = nullptr);

/// A model's distribution over the K candidates completed with a prior's weight on the other
/// bones (models::PriorOptions::keep_prior_outside; not in the papers). `W` (#V×#B) holds the
/// distribution scattered to bones: row v is nonzero only on v's candidates C(v) (`character`'s
/// `distance` top-K) and sums to 1. With P = `character`'s prior `prior` (#V×#B, rows summing
/// to 1) and m_v = Σ_{b ∈ C(v)} P[v, b], row v becomes
///
///     W'[v, b] = m_v · W[v, b]   for b ∈ C(v),      W'[v, b] = P[v, b]   otherwise,
///
/// which still sums to 1. The candidates keep the prior's total mass on them, split as the model
/// predicts; the weight HeterSkinNet's top-K candidates (Sec. 3.2) cannot express stays the
/// prior's. For W = P renormalised over C(v) (a zero head with the prior's logit bias) W' = P.
/// Throws Error naming the character when it has no such prior or its shapes differ.
void keep_prior_outside(data::RowMatrixXd& W, const data::PreparedCharacter& character,
                        const std::string& distance, const std::string& prior);

/// A model's bone weights mixed with a prior's (models::PriorOptions::prior_mix; not in the
/// papers): W ← (1 − α)·W + α·P for `character`'s prior `prior` P (#V×#B, as W), α = `alpha`
/// in [0, 1]. Rows that sum to 1 still do. A convex combination of the learned weights and the
/// classical method's, for characters from sources the network did not train on, where the two
/// err differently and the mix can err less than either (α is chosen on such sources;
/// experiments/heterskinnet/README.md measures where it does). Throws Error naming the character
/// when it has no such prior or its shape differs, or for α outside [0, 1].
void mix_prior(data::RowMatrixXd& W, const data::PreparedCharacter& character,
               const std::string& prior, double alpha);

/// What evaluation and prediction do with a model's prior after its forward pass (the fields
/// of models::PriorOptions that act there): keep it off the candidates, then mix it in.
struct PriorUse {
  std::string prior;          ///< a key of PreparedCharacter::priors; empty: the model reads none
  bool keep_outside = false;  ///< keep_prior_outside
  double mix = 0;             ///< mix_prior's α; 0: the model's weights alone

  /// Whether use_prior changes a model's weights.
  bool acts() const { return !prior.empty() && (keep_outside || mix > 0); }
};

/// `W` (#V×#B, the model's weights scattered to bones) completed as `use` says: keep_prior_outside
/// when `use.keep_outside`, then mix_prior when `use.mix` > 0; unchanged unless `use.acts()`.
void use_prior(data::RowMatrixXd& W, const data::PreparedCharacter& character,
               const std::string& distance, const PriorUse& use);

/// Step 4: `candidates` (#V×K, the network's softmax over `input.prepared`'s candidates of
/// `distance`) scattered to bones, completed with the model's prior as `prior` says (use_prior),
/// pruned, checked (every vertex keeps a weight) and mapped back to the input's vertices and
/// joints; `input.prepared` moves into the result.
/// Throws Error naming the character and the vertex for a non-finite or negative output or a
/// vertex left without weight. `times->map_back` receives the mapping back.
Prediction finish_prediction(PreparedInput input, const std::string& distance,
                             data::RowMatrixXf candidates, double prune,
                             const PriorUse& prior = {}, StageTimes* times = nullptr);

/// Step 4 for weights that are already per bone: `W` (#V×#B at `input.prepared`'s vertices,
/// from `method`, e.g. "binder 'bone_heat'", which error messages name) checked (finite, ≥ 0),
/// pruned, checked again (every vertex keeps a weight) and mapped back as finish_prediction
/// does; the result's `candidates` is empty. `times->network` receives the checks and pruning.
Prediction finish_bone_weights(PreparedInput input, const std::string& distance,
                               data::RowMatrixXd W, double prune, const std::string& method,
                               StageTimes* times = nullptr);

}  // namespace skinlab::infer

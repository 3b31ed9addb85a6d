#pragma once
/// \file
/// One prepared character as the libtorch tensors a network, a loss and a metric consume
/// (HeterSkinNet Sec. 3.2–3.4). Made from a PreparedCharacter (dataset_file.hpp) for one
/// distance type; everything is in the normalised frame (Y up, 1 m tall).
///
/// Conventions shared by models (framework/models/), graph ops (framework/graph/) and metrics
/// (framework/eval/):
/// - floating tensors are float32, index tensors int64, all on the CPU;
/// - an edge list is #E×2 (i, j): vertex i receives a message from its neighbour j (the layout
///   of the dataset file's `edges/*`), both directions of every undirected edge present;
/// - the candidate bones of vertex v are topk_index[v, 0..K), nearest first under the chosen
///   distance; a model predicts a distribution over them (#V×K, rows sum to 1), and
///   `scatter_to_bones` turns it into #V×#B bone weights.

#include <torch/torch.h>

#include <map>
#include <string>

#include "framework/data/dataset_file.hpp"

namespace skinlab::data {

struct CharacterTensors {
  std::string name;
  std::string distance;     ///< distance registry key the top-K and targets come from
  torch::Tensor positions;  ///< #V×3 float32 vertex positions
  /// #V×3 float32 unit area-weighted vertex normals of the faces oriented outwards per part
  /// (geometry/orient_outward.hpp, vertex_normals.hpp); zero for a vertex on no face
  torch::Tensor normals;
  torch::Tensor topk_index;     ///< #V×K int64 candidate bones, nearest first
  torch::Tensor topk_distance;  ///< #V×K float32 their distances (metres), ascending
  /// #V×K float32 ground-truth distribution over the candidates: the dataset's `targets`
  /// renormalised per row (weight outside the K candidates is dropped, Sec. 3.2); a row whose
  /// candidates carry no weight at all stays all-zero.
  torch::Tensor targets;
  /// #V×#B float32 full ground-truth bone weights, rows sum to 1; undefined for a character
  /// prepared without weights (for prediction)
  torch::Tensor bone_weights;
  /// Per prior the character was prepared with (PreparedCharacter::priors, e.g. "bone_heat"):
  /// #V×K float32, that method's weight on each candidate bone; a row sums to ≤ 1 (its weight on
  /// other bones is not there). Empty for a file prepared without priors.
  std::map<std::string, torch::Tensor> priors;
  torch::Tensor bones;         ///< #B×6 float32 bone attribute [start xyz, end xyz] (Sec. 3.2)
  torch::Tensor bone_joints;   ///< #B×2 int64 (start, end) joint of each bone
  torch::Tensor one_ring;      ///< #E×2 int64 mesh edges (N_m of Eq. 2)
  torch::Tensor geodesic;      ///< #E_g×2 int64 geodesic-neighbour edges (N_g of Eq. 2)
  torch::Tensor laplacian;     ///< #V×#V float32 sparse COO uniform Laplacian (Eq. 6)

  std::int64_t num_vertices() const { return positions.size(0); }
  std::int64_t num_bones() const { return bones.size(0); }
  std::int64_t top_k() const { return topk_index.size(1); }
};

/// Builds the tensors of `character` for distance type `distance`. Throws IoError naming the
/// character and listing the distance types it has when `distance` is not among them.
CharacterTensors to_tensors(const PreparedCharacter& character, const std::string& distance);

/// A float32 copy of `m` (rows × cols), e.g. vertex positions.
torch::Tensor to_float(const RowMatrixXd& m);
/// An int64 copy of `m`, e.g. an #E×2 edge list.
torch::Tensor to_long(const RowMatrixXi& m);

/// `c`'s prior `name` (#V×K, CharacterTensors::priors). Throws Error naming the character, the
/// priors it has and the preparation option that adds `name` (`preprocess.priors`); `who` (the
/// model or binder asking) starts the message.
const torch::Tensor& prior_of(const CharacterTensors& c, const std::string& name,
                              const std::string& who);

/// #V×#B bone weights from a #V×K distribution over the candidates `topk_index` (#V×K):
/// out[v, topk_index[v, k]] = pred[v, k], zero elsewhere. Differentiable in `pred`.
torch::Tensor scatter_to_bones(const torch::Tensor& pred, const torch::Tensor& topk_index,
                               std::int64_t num_bones);

}  // namespace skinlab::data

#pragma once
/// \file
/// HeterSkinNet's forward pass (Pan et al., I3D 2021, Sec. 3.2–3.3, Fig. 3) in Eigen float32,
/// without libtorch, for `skinlab-predict`: the network a parameter file describes
/// (infer/parameters.hpp, written from the libtorch model by `skinlab bundle`), evaluated on
/// one prepared character,
///
///     f_v = [p ‖ 1/max(D/unit, min)]  (K + 3),   f_b = [start ‖ end]  (6)      Sec. 3.2
///     x   = stem(f_v, f_b);   G = global(x);   l = local(x)
///     w_v = softmax(MLP_head(l_v ‖ l_b[n_v,1] ‖ … ‖ l_b[n_v,K] ‖ G))
///
/// and for a model trained with a prior (models::PriorOptions, not in the paper) q_v, a
/// classical method's weight on the K candidates: f_v = [p ‖ 1/D ‖ q_v] (2K + 3) and, with
/// `prior_bias`, w_v = softmax(MLP_head(…) + log(q_v + prior_epsilon)); a `leaf_bias` in the
/// architecture (models::BranchedModelOptions::leaf_bias) is added to the logits of the
/// candidates that are a leaf joint's bone before the softmax;
/// with the graph ops of the libtorch implementation (framework/graph/), each the same map:
///   - `b2v` (Eq. 5): MLP(f_v ‖ f_{b_{n_v,1}} ‖ … ‖ f_{b_{n_v,K}}), layer 0 split by weight
///     blocks so the bone blocks cost #B rows (graph/mlp.hpp, forward_gathered);
///   - `v2b` (Eq. 4): MLP(f_b ‖ max ‖ mean ‖ 0.1·var over the vertices with b among their K
///     candidates), population variance in two passes, zeros for a bone no vertex lists;
///   - `edge_conv` (Eq. 2, EdgeConv with max, self-loop included) and `mesh_conv` (Eq. 3: one
///     EdgeConv per mesh edge set, concatenated, then an MLP): layer 0 applied per node,
///     W[x_i ; x_i − x_j] + b = (W₁+W₂)x_i + b − W₂x_j, and for a one-layer MLP the max moved
///     inside the non-decreasing activation, σ(a_i − min_j b_j) (graph/aggregate.hpp);
///   - `global_pool` (Fig. 3's global branch): max over the nodes of MLP(f_n) (or MLP of the
///     max), per pooled subgraph, broadcast to the receiving nodes;
/// and LeakyReLU(0.2) after every MLP layer but the head's last (Sec. 4.2). Dropout is a
/// training-time operation and absent here. Products run in parallel blocks of rows on TBB's
/// threads (tbb::global_control limits them). The outputs equal the libtorch path's up to
/// float rounding (tests/predict/eigen_network_test.cpp: within 1e-5).
///
/// network.cpp is built for AVX2 and FMA when the building machine has them
/// (framework/CMakeLists.txt) and keeps its Eigen in a namespace of its own, so its interface
/// takes and gives plain arrays (NetworkInput, std::vector): no Eigen object built with one set
/// of alignment and allocation rules is used or freed under the other. infer::forward
/// (eigen_predictor.hpp) is the call on a prepared character.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/infer/parameters.hpp"

namespace skinlab::infer {

/// One prepared character (data/preprocess.hpp) as the row-major arrays the network reads.
struct NetworkInput {
  std::string name;               ///< for messages
  std::int64_t num_vertices = 0;  ///< #V
  std::int64_t num_bones = 0;     ///< #B
  std::int64_t top_k = 0;         ///< K
  const double* positions = nullptr;      ///< #V×3, the normalised frame
  const float* topk_distance = nullptr;   ///< #V×K, metres
  const int* topk_index = nullptr;        ///< #V×K candidate bones, nearest first
  const int* one_ring = nullptr;          ///< #E×2 (receiver, neighbour)
  std::int64_t num_one_ring = 0;          ///< #E
  const int* geodesic = nullptr;          ///< #E_g×2
  std::int64_t num_geodesic = 0;          ///< #E_g
  const int* bones = nullptr;             ///< #B×2 (start, end) joints
  const double* bone_segments = nullptr;  ///< #B×6 [start, end] (Sec. 3.2's bone attribute)
  const float* prior = nullptr;  ///< #V×K: Network::prior()'s weight on each candidate, if any
};

class Network {
 public:
  /// The network `parameters` (read from `file`) describes. IoError naming `file` and the
  /// element for: a model type other than heterskinnet; an op this forward pass does not
  /// implement (named with its place, e.g. "op 'local.2_gat_block' (type gat_block)"); a
  /// missing architecture field; a missing, extra or wrongly shaped parameter.
  static Network from(const ParameterFile& parameters, const std::filesystem::path& file);

  /// #V×K row-major: the softmax over the candidate bones of every vertex of `input`. Error
  /// naming the character for a K other than the model's, a candidate that is not a bone, an
  /// edge that is not between two nodes, or a missing `prior` when the model reads one.
  std::vector<float> forward(const NetworkInput& input) const;

  int top_k() const;
  /// The prior the model reads (a binder's registry key, e.g. "bone_heat"); empty: none.
  const std::string& prior() const;
  /// Whether predictions keep the prior's weight off the candidates
  /// (models::PriorOptions::keep_prior_outside, infer::keep_prior_outside); false without a prior.
  bool keep_prior_outside() const;
  /// α of the mix with the prior after the network (models::PriorOptions::prior_mix,
  /// infer::mix_prior); 0 without a prior.
  double prior_mix() const;

  Network(Network&&) noexcept;
  Network& operator=(Network&&) noexcept;
  ~Network();

 private:
  struct Impl;
  explicit Network(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace skinlab::infer

#pragma once
/// \file
/// `heterskinnet`: HeterSkinNet (Pan et al., I3D 2021), Sec. 3 and Fig. 3, with the sizes of
/// Sec. 4.2, assembled from `graph_op` plug-ins so that every component is a config entry.
///
/// Inputs (Sec. 3.2): vertex attribute f_v = [p, 1/D of the K candidate bones] (K + 3), bone
/// attribute f_b = [start, end] (6). D is the distance type of the run's `data.distance`,
/// measured in units of `distance_unit` (default: one HollowDist cell of the 88³ grid, Sec. 4.2,
/// i.e. 1/88 of the normalised 1 m frame) and clamped below at `min_distance` such units, so
/// 1/D ≤ 1/min_distance. The paper states 1/D without a unit. In metres 1/D reaches 10³ (a
/// vertex on a bone) against positions within ±0.5: measured on the bundled characters, the
/// freshly initialised network then put > 0.999 of every row on one bone for 85–100 % of the
/// vertices, and the validation loss did not move in training (saturated softmax). In cells,
/// 1/D ≤ 1 is on the scale of the positions.
///
/// Network (Fig. 3):
///
///     x   = stem(f_v, f_b)       # inter-graph conv, then the two intra-graph convs
///     G   = global(x)            # max-pool + MLP per subgraph: vertex 512 ‖ bone 512
///     l   = local(x)             # alternately stacked intra- and inter-graph convs
///     h_v = l_v ‖ l_b[n_v,1] ‖ … ‖ l_b[n_v,K] ‖ G    # bones scattered to their vertices
///     w_v = softmax(MLP_head(h_v))                    # [1024, 512, K], 50 % dropout
///
/// Evaluation and prediction may add `leaf_bias` to the logits of the candidates that are a leaf
/// joint's bone (models::BranchedModelOptions::leaf_bias; not in the paper): a calibration chosen
/// on the validation part after training, against the network's measured habit of giving a
/// leaf's region to its parent (experiments/heterskinnet/README.md).
///
/// A character with fewer bones than K has only that many candidates (data/preprocess.hpp); its
/// candidates (index, distance, prior) are padded to K with the nearest one again, and the padded
/// slots' logits are dropped before the softmax, so w_v is a distribution over its own candidates
/// (#V × its K; data::candidates_for_model, shared with RigNet's and NeuroSkinning's networks).
/// infer/network.cpp does the same for `skinlab-predict`. Not in the paper: Sec. 3.2
/// takes the K nearest bones and does not say what a character with fewer bones gets.
///
/// `stem`, `local` (lists of ops, graph/graph_op.hpp) and `global` (one op) are config nodes;
/// their defaults are the paper's widths (vertex local 256, bone local 128, global 512 + 512).
/// Mesh-edge dropout (85 % of one-ring and geodesic edges, Sec. 4.2, graph/edge_dropout.hpp) is
/// drawn once per forward pass in training mode; the head's dropout (50 %) likewise only trains.
/// The paper does not give the depth of the local branch; `local` defaults to two blocks of
/// [b2v, v2b, mesh_conv, edge_conv] (RigNet's skinning network, whose GCU it adopts, uses three
/// GCU blocks; the stem is the first).
///
/// A prior (not in the paper): with `prior: bone_heat` the network starts from a classical
/// method's weights, prepared into the dataset (data/preprocess.hpp step 4b, `preprocess.priors`).
/// Its weight on the K candidates, p_v (#V×K, CharacterTensors::priors), is appended to f_v
/// (2K + 3 inputs), and with `prior_bias` (default true) log(p_v + prior_epsilon) is added to the
/// head's logits before the softmax:
///
///     w_v = softmax(MLP_head(h_v) + log(p_v + ε))
///
/// so a head that outputs zeros reproduces the prior renormalised over the K candidates, and
/// training learns where artists depart from it (a multiplicative correction per candidate).
/// ε (1e-3) bounds the correction needed to give weight to a candidate the prior leaves at 0
/// (|log ε| ≈ 6.9). Motivation, measured: on games from unseen sources bone heat had lower L1
/// than the network (experiments/heterskinnet/README.md, "Skinning beyond one game").
/// `keep_prior_outside: true` changes only evaluation and prediction: the prior keeps its own
/// weight on the bones outside the K candidates and the candidates share the prior's mass on
/// them as w_v says (infer::keep_prior_outside), so a zero head reproduces the prior itself.
/// `prior_mix: α` (evaluation and prediction only) then returns (1 − α)·w + α·p, the network's
/// bone weights mixed with the prior's (infer::mix_prior), for sources the network has not seen.
///
/// Ablations are configs: `configs/ablations/no_heterconv.yaml` lists `local`/`stem` without the
/// `b2v`/`v2b` ops (the head still reads the K candidates' bone features: without an
/// inter-graph conv those are the bone attributes processed by skeleton convs only).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/graph/edge_dropout.hpp"
#include "framework/graph/graph_op.hpp"
#include "framework/graph/mlp.hpp"
#include "framework/models/branched_model.hpp"
#include "framework/models/model.hpp"

namespace skinlab::experiments {

class HeterSkinNet final : public models::Model {
 public:
  /// top_k (K = 3, Sec. 4.2), distance_unit, min_distance, stem/local/global (missing: the
  /// paper's widths), head [1024, 512] and head_dropout 0.5: models/branched_model.hpp.
  struct Options : models::BranchedModelOptions, models::PriorOptions {
    graph::EdgeDropoutOptions edge_dropout;
    static Options from(const config::Node& node);
  };
  explicit HeterSkinNet(Options options);

  torch::Tensor forward(const data::CharacterTensors& c) override;

 private:
  Options options_;
  std::shared_ptr<graph::Sequence> stem_, local_;
  std::shared_ptr<graph::GraphOp> global_;
  graph::Mlp head_{nullptr};
};

}  // namespace skinlab::experiments

#pragma once
/// \file
/// What the models assembled from `graph_op` branches share (`heterskinnet`,
/// experiments/heterskinnet/; `rignet_skin`, baselines/rignet_skin/; `neuroskinning`,
/// baselines/neuroskinning/): the K candidate bones, the 1/D input and its unit, the `stem` /
/// `local` / `global` op lists, and the head MLP; and `BranchedNetwork`, the whole network of
/// the two baselines, which differ only in their input features and their ops.
///
/// 1/D is measured in `distance_unit`s (default one HollowDist cell, 1/88 of the normalised 1 m
/// frame, HeterSkinNet Sec. 4.2) and D is clamped below at `min_distance` units, so 1/D ≤
/// 1/min_distance. In metres 1/D reaches 10³ for a vertex on a bone: both networks then started
/// with one-hot rows (a saturated softmax) and did not learn (see heterskinnet.hpp).

#include <torch/torch.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/graph/graph_op.hpp"
#include "framework/graph/mlp.hpp"
#include "framework/models/model.hpp"

namespace skinlab::models {

struct BranchedModelOptions {
  std::int64_t top_k = 3;             ///< K; must equal the dataset's top-K
  double distance_unit = 1.0 / 88.0;  ///< metres per unit of D (one 88³ HollowDist cell)
  double min_distance = 1.0;          ///< in `distance_unit`s; D is clamped to this before 1/D
  config::Node stem, local, global;   ///< op lists / op node; missing: the model's defaults
  std::vector<std::int64_t> head = {1024, 512};  ///< hidden widths before the K logits
  double head_dropout = 0.5;
  /// Evaluation and prediction only (not in the papers): added to the logit of every candidate
  /// that is a leaf joint's bone (start joint = end joint; models::leaf_candidates) before the
  /// softmax, i.e. each leaf candidate's weight multiplied by e^leaf_bias and the row
  /// renormalised. A calibration chosen on the validation part after training
  /// (scripts/calibrate_leaf_bias); training never sees it. 0: none.
  double leaf_bias = 0;

  /// Reads and checks these fields from `f` (call before `f.finish()`).
  void read(config::Fields& f);
  /// Fills `stem`, `local` and `global` that the config left out from the model's defaults,
  /// `defaults_yaml` (a string literal with those three keys; parsed once per literal and kept
  /// for the life of the program, so the filled nodes stay valid).
  void fill_missing_branches(const char* defaults_yaml);
};

/// A prior a model may start from (not in the papers): `prior` names one of the priors a
/// dataset was prepared with (data/preprocess.hpp step 4b, CharacterTensors::priors), p_v its
/// weight on the K candidates (#V×K). A model reading it appends p_v to its vertex input and,
/// with `prior_bias`, adds log(p_v + prior_epsilon) to its logits before the softmax
/// (experiments/heterskinnet/heterskinnet.hpp). Here so the parameter export
/// (predict/parameter_export.hpp) records exactly what skinlab-predict's forward pass must apply.
struct PriorOptions {
  std::string prior;         ///< a key of CharacterTensors::priors; empty: none (the papers)
  bool prior_bias = true;    ///< add log(p + prior_epsilon) to the logits (needs `prior`)
  double prior_epsilon = 1e-3;
  /// Evaluation and prediction only (training fits the distribution over the candidates, as
  /// without it): keep the prior's own weight on the bones outside the K candidates and give
  /// the candidates the prior's mass on them, split as the model predicts
  /// (infer::keep_prior_outside). With `prior_bias`, a head of zeros then reproduces the prior
  /// itself instead of the prior renormalised over the candidates. Needs `prior`.
  bool keep_prior_outside = false;
  /// Evaluation and prediction only: α in [0, 1] of the mix (1 − α)·model + α·prior of the
  /// bone weights, after keep_prior_outside and before pruning (infer::mix_prior); 0: the
  /// model's weights alone. Needs `prior` when above 0.
  double prior_mix = 0;

  /// Reads and checks `prior`, `prior_bias`, `prior_epsilon`, `keep_prior_outside` and
  /// `prior_mix` from `f` (call before `f.finish()`): ConfigError for prior_epsilon ≤ 0, a
  /// prior_mix outside [0, 1], or a `prior_bias`, `keep_prior_outside` or `prior_mix` > 0
  /// without a `prior`.
  void read(config::Fields& f);
  /// The prior options of the model config node `model` (`{type: ..., prior: ..., ...}`; a
  /// model that reads no prior gives the defaults with an empty `prior`), checked as by read.
  static PriorOptions of(const config::Node& model);
};

/// #V×K: 1 where candidate k of vertex v is a leaf joint's bone (start joint = end joint of
/// c.bone_joints: the helper bone at a joint without children), else 0; float32.
torch::Tensor leaf_candidates(const data::CharacterTensors& c);

/// `logits` (#V×K over c's candidates) with `leaf_bias` (BranchedModelOptions::leaf_bias) added
/// to the leaf candidates' when `training` is false and leaf_bias is not 0; `logits` otherwise.
torch::Tensor with_leaf_bias(const torch::Tensor& logits, const data::CharacterTensors& c,
                             double leaf_bias, bool training);

/// #V×K: 1 / max(D / distance_unit, min_distance) of the candidates' distances (#V×K metres).
torch::Tensor inverse_distance(const torch::Tensor& topk_distance,
                               const BranchedModelOptions& options);

/// The network RigNet's skinning network (Xu et al. 2020, Sec. 3.3) and NeuroSkinning (Liu et al.
/// 2019, Fig. 3) both are, given per-vertex input features f_v:
///
///     x0 = MLP_input(f_v)          # per vertex, shared ("multi-layer transform")
///     x1 = stem(x0)                # graph ops
///     g  = global(x1)              # e.g. max-pooled MLP, repeated to every vertex
///     x3 = local(x1)               # graph ops
///     w  = softmax(head(x3 ‖ g))   # over the K candidate bones
///
/// Submodules `input`, `stem`, `local`, `global_branch` ("global" is a Python keyword, which
/// libtorch checkpoints cannot store as a module name) and `head`. Bone attributes [start, end]
/// (width 6) ride along, so a config may add skeleton ops; neither baseline uses any.
/// The layers of a branched network: MLP_input → stem → (global ‖ local) → head, registered on
/// `owner` under the names `input`, `stem`, `local`, `global_branch` and `head`. Shared by the
/// skinning BranchedNetwork (RigNet's and NeuroSkinning's networks) and the corrective task's
/// NeuroSkinning network (experiments/densegats), which differ in inputs and outputs only.
class BranchedLayers {
 public:
  BranchedLayers() = default;
  /// `name` prefixes messages; `input_width` is the width of f_v, `input_mlp` the widths of
  /// MLP_input, `bone_width` the width of the bone features the stem receives (0: none) and
  /// `outputs` the head's last width (no activation after it).
  BranchedLayers(torch::nn::Module& owner, const std::string& name,
                 const BranchedModelOptions& options, std::int64_t input_width,
                 const std::vector<std::int64_t>& input_mlp, std::int64_t bone_width,
                 std::int64_t outputs);
  /// #V×outputs: the head on [local ‖ global] for #V×input_width `features` and the bone
  /// features `bones` (undefined when bone_width is 0).
  torch::Tensor forward(const torch::Tensor& features, const torch::Tensor& bones,
                        const graph::Graph& graph);
  graph::Mlp& head() { return head_; }

 private:
  graph::Mlp input_{nullptr}, head_{nullptr};
  std::shared_ptr<graph::Sequence> stem_, local_;
  std::shared_ptr<graph::GraphOp> global_;
};

class BranchedNetwork : public Model {
 public:
  /// #V×K softmax over the candidates `c.topk_index`; for a character with fewer bones than K,
  /// over its own candidates (data::candidates_for_model).
  torch::Tensor forward(const data::CharacterTensors& c) override;
  /// The #V×`input_width` features f_v.
  virtual torch::Tensor input_features(const data::CharacterTensors& c) const = 0;

 protected:
  /// `name` (the registry key) prefixes messages; `input_width` is the width of f_v and
  /// `input_mlp` the widths of MLP_input. Builds and registers every submodule.
  BranchedNetwork(std::string name, const BranchedModelOptions& options, std::int64_t input_width,
                  const std::vector<std::int64_t>& input_mlp);

 private:
  std::string name_;
  std::int64_t top_k_;
  double leaf_bias_;
  BranchedLayers layers_;
};

}  // namespace skinlab::models

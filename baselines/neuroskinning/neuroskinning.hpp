#pragma once
/// \file
/// `neuroskinning`: the network of NeuroSkinning (Liu et al., "NeuroSkinning: Automatic Skin
/// Binding for Production Characters with Deep Graph Networks", ACM TOG 38(4), SIGGRAPH 2019),
/// the NeuroSkinning row of HeterSkinNet's Table 3. HeterSkinNet Sec. 4.5: the dataset's
/// skeletons "cannot fit into a super-skeleton", so only "their network architecture and their
/// way in selecting the nearest bones, i.e., based on the Euclidean distance" are used, trained
/// on the same split with the same hyper-parameters (K = 3, 0.25 pruning):
/// configs/baselines/neuroskinning.yaml (`data.distance: euclidean`).
///
/// Network, from the paper's Fig. 3 (github.com/FuxiCV/NeuroSkinning, `imgs/pipeline.jpg`; no
/// code was published), widths as the figure:
///
///     x0 = MLT[64](f_v)                       # "multi-layer transform": a shared MLP
///     x1 = GCU_256(x0)                        # 64 → 576           (stem)
///     g  = repeat(max_v MLT[1024](x1))        # 1024, global       (global)
///     x3 = GCU_128(GCU_128(x1))               # 576 → 832 → 1088   (local)
///     w  = softmax(MLT(x3 ‖ g))               # over the K candidates
///
/// GCU_h is the `gconv_pool` op (graph/gconv_pool.hpp): x ‖ h ‖ maxpool(h) with h a graph
/// convolution of width h on the mesh adjacency. This is `models::BranchedNetwork` with
/// NeuroSkinning's inputs and ops, the same shape as RigNet's network, which also pools the
/// first unit's output; the difference is the unit (GCN + pooling + skip concatenation vs two
/// EdgeConvs) and the input.
///
/// Input. The figure's node attributes are N×(6 + |B|): six per-vertex values and one value per
/// bone of the super-skeleton. We read the six as the vertex position and its normal (the
/// figure does not name them), and, with no super-skeleton, the |B| bone values become one per
/// candidate: 1/D of the K bones nearest by Euclidean distance, nearest first, D in
/// `distance_unit`s clamped at `min_distance` as for the other networks:
///
///     f_v = p ‖ n ‖ [1/D_1, …, 1/D_K]                                        (6 + K)
///
/// Choices the figure leaves open, each an option: the last transform's widths (`head`,
/// default [512, 256]; the figure draws one block), no dropout, LeakyReLU(0.2) and
/// Kaiming-normal initialisation (the framework's `graph::Mlp`). Loss: the configs use KL
/// against the K candidates' renormalised weights, HeterSkinNet's L_D, as "the same
/// hyper-parameters" suggests; no smoothing term.

#include <cstdint>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/models/branched_model.hpp"

namespace skinlab::baselines {

class NeuroSkinning final : public models::BranchedNetwork {
 public:
  /// top_k, distance_unit, min_distance, stem/local/global (missing: the figure's widths) and
  /// head as models/branched_model.hpp.
  struct Options : models::BranchedModelOptions {
    Options() {
      head = {512, 256};
      head_dropout = 0.0;
    }
    bool normals = true;                         ///< the three normal components in f_v
    std::vector<std::int64_t> input_mlp = {64};  ///< the first multi-layer transform
    static Options from(const config::Node& node);
  };
  explicit NeuroSkinning(Options options);

  /// The #V×(6 + K) (3 + K without normals) input features f_v. Requires `c.normals`.
  torch::Tensor input_features(const data::CharacterTensors& c) const override;

  const Options& options() const { return options_; }

 private:
  Options options_;
};

}  // namespace skinlab::baselines

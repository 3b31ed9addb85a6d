#pragma once
/// \file
/// `rignet_skin`: the skinning network of RigNet (Xu et al., "RigNet: Neural Rigging for
/// Articulated Characters", SIGGRAPH 2020, Sec. 3.3), the RigNet row of HeterSkinNet's Table 3.
/// HeterSkinNet Sec. 4.5 re-implements it with the volumetric geodesic distance (not RigNet's
/// approximation) and trains it on the same split with the same hyper-parameters (K = 3
/// influential bones, 0.25 pruning): configs/baselines/rignet_skin.yaml.
///
/// Facts from RigNet's public code (github.com/zhan-xu/RigNet, commit 589a928):
/// - Input (gen_dataset.py l. 121–136, datasets/skin_dataset.py l. 54–67, models/SKINNING.py
///   l. 23–55): per vertex, its position, then for each of the K candidate bones nearest by
///   volumetric geodesic distance, nearest first, the bone's [start xyz, end xyz] (common_ops.py
///   `get_bones`), 1/D_g, and a leaf flag (1 for the virtual zero-length bone at a leaf joint):
///
///       f_v = p ‖ [s_1, e_1, 1/D_1, leaf_1] ‖ … ‖ [s_K, e_K, 1/D_K, leaf_K]     (3 + 8K)
///
///   The leaf flag is the `--Lf` option; the README's training command uses `--Dg --Lf`.
/// - Network (SKINNING.py l. 31–38, 57–68; GCU in models/gcn_basic_modules.py l. 48–62):
///
///       x0 = MLP[128, 64](f_v)
///       x1 = GCU(64 → 512)(x0)              # stem
///       g  = max_v MLP[512, 1024](x1)       # global, from x1 (not from x3)
///       x3 = GCU(256 → 256)(GCU(512 → 256)(x1))    # local
///       logits = MLP[1024, 512, K](x3 ‖ g)  # softmax over the K candidates
///
///   GCU(in → out) = MLP[out](EdgeConv_one-ring ‖ EdgeConv_geodesic), each EdgeConv with the
///   message MLP[out/2, out/2] on (x_i ‖ x_j − x_i), max aggregation, self-loops added: our
///   `mesh_conv` with `edge_mlp: [out/2, out/2], mlp: [out]`. The GCUs are config lists of
///   `graph_op`s (`stem`, `local`), the global branch is a `global_pool` op; the input MLP and the
///   head are width options, as in `heterskinnet`.
/// - Loss (run_skinning.py, models/supplemental_layers/cross_entropy_with_probs.py): soft
///   cross-entropy of the softmax against the ground-truth weights of the K candidates
///   renormalised to sum 1; no smoothness term. That is our `soft_cross_entropy` loss.
///
/// Deviations (each a choice of the framework, not of RigNet):
/// - 1/D is measured in `distance_unit`s (default 1/88 m, HeterSkinNet's HollowDist cell) and D
///   is clamped below at `min_distance` units, as in `heterskinnet`: RigNet computes
///   1/(D + 1e-10) in its ~1-high units (up to 10¹⁰ on a bone), which its batch norm after the
///   first layer absorbs; without batch norm it saturates the softmax at initialisation.
/// - No BatchNorm1d (RigNet has one after every ReLU) and LeakyReLU(0.2) with Kaiming-normal
///   init instead of ReLU with PyTorch's default init: the framework's `graph::Mlp`, shared with
///   HeterSkinNet. The EdgeConv message is MLP(x_i ‖ x_i − x_j) (graph/edge_conv.hpp), the
///   negated difference of RigNet's; the first layer absorbs the sign, so the function class is
///   the same.
/// - RigNet's test-time post-filter (one-ring mean of neighbours' weights, then dropping weights
///   below half the vertex's maximum, run_skinning.py `post_filter`) is not applied: every
///   Table 3 method goes through the same evaluation (0.25 pruning).
/// - The loss is a mean over vertices (RigNet: over (vertex, candidate) entries, i.e. ours / K,
///   excluding vertices whose candidates carry no weight; here they contribute 0 but count).

#include <cstdint>
#include <memory>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/models/branched_model.hpp"

namespace skinlab::baselines {

class RigNetSkin final : public models::BranchedNetwork {
 public:
  /// top_k (K = 3, HeterSkinNet Sec. 4.5), distance_unit, min_distance, stem/local/global
  /// (missing: RigNet's widths) and head as models/branched_model.hpp; RigNet's head has no
  /// dropout.
  struct Options : models::BranchedModelOptions {
    Options() { head_dropout = 0.0; }
    bool leaf_flag = true;  ///< RigNet's `--Lf` input (8 values per bone, else 7)
    std::vector<std::int64_t> input_mlp = {128, 64};  ///< SKINNING.py l. 31
    static Options from(const config::Node& node);
  };
  explicit RigNetSkin(Options options);

  /// The #V×(3 + 8K) (or 3 + 7K without the leaf flag) input features f_v.
  torch::Tensor input_features(const data::CharacterTensors& c) const override;

  const Options& options() const { return options_; }

 private:
  Options options_;
};

}  // namespace skinlab::baselines

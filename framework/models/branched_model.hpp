#pragma once
/// \file
/// What the models assembled from `graph_op` branches share (`heterskinnet`,
/// experiments/heterskinnet/; `rignet_skin`, baselines/rignet_skin/): the K candidate bones,
/// the 1/D input and its unit, the `stem` / `local` / `global` op lists, and the head MLP.
///
/// 1/D is measured in `distance_unit`s (default one HollowDist cell, 1/88 of the normalised 1 m
/// frame, HeterSkinNet Sec. 4.2) and D is clamped below at `min_distance` units, so 1/D ≤
/// 1/min_distance. In metres 1/D reaches 10³ for a vertex on a bone: both networks then started
/// with one-hot rows (a saturated softmax) and did not learn (see heterskinnet.hpp).

#include <torch/torch.h>

#include <cstdint>
#include <vector>

#include "framework/core/config.hpp"

namespace skinlab::models {

struct BranchedModelOptions {
  std::int64_t top_k = 3;             ///< K; must equal the dataset's top-K
  double distance_unit = 1.0 / 88.0;  ///< metres per unit of D (one 88³ HollowDist cell)
  double min_distance = 1.0;          ///< in `distance_unit`s; D is clamped to this before 1/D
  config::Node stem, local, global;   ///< op lists / op node; missing: the model's defaults
  std::vector<std::int64_t> head = {1024, 512};  ///< hidden widths before the K logits
  double head_dropout = 0.5;

  /// Reads and checks these fields from `f` (call before `f.finish()`).
  void read(config::Fields& f);
  /// Fills `stem`, `local` and `global` that the config left out from `defaults`' root.
  void fill_missing_branches(const config::Config& defaults);
};

/// #V×K: 1 / max(D / distance_unit, min_distance) of the candidates' distances (#V×K metres).
torch::Tensor inverse_distance(const torch::Tensor& topk_distance,
                               const BranchedModelOptions& options);

}  // namespace skinlab::models

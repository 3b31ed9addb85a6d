#pragma once
/// \file
/// A character's candidate bones as a model built for K of them reads it, when the character has
/// fewer bones than K and so fewer candidates (data/preprocess.hpp takes min(K, #B) per vertex).
/// The paper takes the K nearest bones (HeterSkinNet Sec. 3.2) and does not say what a smaller
/// skeleton gets; every skinning model here (HeterSkinNet, RigNet's and NeuroSkinning's
/// networks) pads and drops as below, and skinlab-predict's Eigen network does the same.

#include <cstdint>
#include <string>

#include "framework/tensors/tensors.hpp"

namespace skinlab::data {

/// `c` as a model built for K = `k` candidates reads it. With k candidates: `c` itself. With fewer
/// bones than k, and so one candidate per bone (data/preprocess.hpp): a copy whose candidates
/// (topk_index, topk_distance and every prior) are padded to k columns with the nearest one
/// again; the model keeps only the first `c.top_k()` logits before its softmax, so its weights
/// are a distribution over `c`'s own candidates (#V×c.top_k()). Any other candidate count is a
/// mismatch: c10::Error naming `who` (the model), the character and the counts.
CharacterTensors candidates_for_model(const CharacterTensors& c, std::int64_t k,
                                      const std::string& who);

}  // namespace skinlab::data

#pragma once
/// \file
/// Interface of the `model` registry: a network that predicts, for every vertex, a distribution
/// over its K candidate bones (HeterSkinNet Sec. 3: softmax over the top-K bones of the chosen
/// distance). Learned models are torch modules so the trainer can optimise, save and load their
/// parameters; every size and component is an option of the model's config node, so ablations
/// are configs, not code.
///
///     model: {type: heterskinnet, top_k: 3, ...}

#include <torch/torch.h>

#include "framework/tensors/tensors.hpp"

namespace skinlab::models {

class Model : public torch::nn::Module {
 public:
  /// #V×K float32, rows sum to 1: the predicted weight of each candidate bone
  /// (`c.topk_index`). Uses dropout only in training mode (`is_training()`).
  virtual torch::Tensor forward(const data::CharacterTensors& c) = 0;
};

}  // namespace skinlab::models

#pragma once
/// \file
/// Interface of the `corrective_model` registry: a network h(G) that predicts, for every vertex
/// of a mesh posed by linear blend skinning, the displacement that corrects it towards the
/// non-linear target (DenseGATs, Li et al. I3D 2020, Sec. 3: deformation = t(S) + h(G)). The
/// skinning `model` registry predicts weights over candidate bones from a rest mesh; this one
/// maps per-vertex attributes of a posed mesh to a displacement, so it is its own category.
///
///     model: {type: densegats, input_width: 52, ...}    # task: corrective (experiments/densegats)
///
/// Every size and component is an option of the model's config node, so the paper's ablations
/// are configs.

#include <torch/torch.h>

#include <cstdint>

#include "framework/graph/graph_op.hpp"

namespace skinlab::models {

class CorrectiveModel : public torch::nn::Module {
 public:
  /// #V×3 float32 displacement from #V×input_width() float32 node attributes over the mesh
  /// edges of `graph` (its one-ring set; bone parts unused). Uses batch statistics and dropout
  /// only in training mode (`is_training()`).
  virtual torch::Tensor forward(const torch::Tensor& features, const graph::Graph& graph) = 0;
  /// The node attribute width the model was built for (the task checks it against its data).
  virtual std::int64_t input_width() const = 0;
};

}  // namespace skinlab::models

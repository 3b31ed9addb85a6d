#pragma once
/// \file
/// `neuroskinning` (corrective_model registry): the NeuroSkinning network (Liu et al., SIGGRAPH
/// 2019) as DenseGATs' Table 3 compares with it ("we evaluated the network described in
/// NeuroSkinning [18] and followed the same experimental settings", Sec. 4.2): the architecture
/// of our skinning baseline (baselines/neuroskinning/neuroskinning.hpp: MLT[64], a 256-wide graph
/// convolution unit, a 1024-wide max-pooled global feature, two 128-wide units, a final
/// transform) on the corrective task's node attributes [p, n, s] (the paper's f_v has the same
/// six values and one per joint), with a 3-wide linear output instead of the softmax over
/// candidate bones. The layers are models::BranchedLayers, the same as the skinning network's.
/// The output layer starts at zero, so training starts from plain LBS, as DenseGATs does.
///
///     model: {type: neuroskinning, input_width: 52}    # configs/densegats/neuroskinning.yaml

#include <cstdint>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/models/branched_model.hpp"
#include "framework/models/corrective_model.hpp"

namespace skinlab::experiments {

class NeuroSkinningCorrective final : public models::CorrectiveModel {
 public:
  /// stem/local/global and head as models/branched_model.hpp (missing: NeuroSkinning's widths);
  /// top_k, distance_unit and min_distance are not used (no candidate bones).
  struct Options : models::BranchedModelOptions {
    Options() {
      head = {512, 256};
      head_dropout = 0.0;
    }
    std::int64_t input_width = 52;
    std::vector<std::int64_t> input_mlp = {64};
    static Options from(const config::Node& node);
  };
  explicit NeuroSkinningCorrective(Options options);

  torch::Tensor forward(const torch::Tensor& features, const graph::Graph& graph) override;
  std::int64_t input_width() const override { return options_.input_width; }

 private:
  Options options_;
  models::BranchedLayers layers_;
};

}  // namespace skinlab::experiments

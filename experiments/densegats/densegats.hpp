#pragma once
/// \file
/// `densegats` (corrective_model registry): DenseGATs (Li et al., "DenseGATs: A
/// Graph-Attention-Based Network for Nonlinear Character Deformation", I3D 2020), Fig. 2:
///
///     g⁰ = [p, n, s]                                   node attributes (Sec. 3.1), 6 + J wide
///     g¹ = feature mapping: Linear → tanh → BatchNorm, `feature_mlp` = [32, 32] (Sec. 3.4)
///     for module m = 1..3:                             dense modules (Sec. 3.3, Eq. 5)
///         x = input;  for b = 1..6:  x = BN(block(x)) ‖ x   (dense: every block sees all
///                                                           earlier outputs of the module)
///         between modules: one more block, the transition ("information integration")
///     head: Linear → tanh → BatchNorm for `head` = [512, 128], then Linear → 3 (displacement)
///
/// `block` is any graph op node, by default `{type: gat_block}` (graph/gat_block.hpp: 8 heads
/// × 8 and a self-reinforced stream with β = 0.125, tanhshrink; 72 wide), so a new convolution
/// is a config change. Every block, the transitions included, gets its own parameters.
///
/// Ablations and comparisons (Table 3) are configs:
/// - w/o self-reinforcement: `block: {type: gat_block, beta: 0}`;
/// - w/o dense connection: `dense: false` (blocks chained, a module's output is its last
///   block's);
/// - the original GAT, "four graph convolutional layers" (Veličković et al. 2018): `modules: 1,
///   blocks_per_module: 4, dense: false, feature_mlp: [], head: [], batch_norm: false,
///   block: {type: gat_block, beta: 0, activation: elu}` (configs/densegats/gat_original.yaml).
///
/// Where the paper is silent, our choices: "All the outputs of layers in the network are
/// applied with 1D batch normalization" is read as BatchNorm1d over the vertices after every
/// feature-mapping layer, every block and every hidden head layer, not after the output layer
/// (a displacement must be free to take any scale); Linear layers start Glorot-uniform with zero
/// bias (the tanh networks' usual initialisation) and the output layer at zero, so training
/// starts from plain LBS.
///
/// Options:
///     input_width: 52          # 6 + J (the 0 A.D. biped skeleton has 46 joints)
///     feature_mlp: [32, 32]
///     modules: 3
///     blocks_per_module: 6
///     dense: true
///     transitions: true        # a block between adjacent modules
///     block: {type: gat_block}
///     head: [512, 128]
///     batch_norm: true

#include <cstdint>
#include <memory>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/graph/graph_op.hpp"
#include "framework/models/corrective_model.hpp"

namespace skinlab::experiments {

class DenseGats final : public models::CorrectiveModel {
 public:
  struct Options {
    std::int64_t input_width = 52;
    std::vector<std::int64_t> feature_mlp = {32, 32};
    int modules = 3;
    int blocks_per_module = 6;
    bool dense = true;
    bool transitions = true;
    config::Node block;  ///< missing: {type: gat_block}
    std::vector<std::int64_t> head = {512, 128};
    bool batch_norm = true;
    static Options from(const config::Node& node);
  };
  explicit DenseGats(Options options);

  torch::Tensor forward(const torch::Tensor& features, const graph::Graph& graph) override;
  std::int64_t input_width() const override { return options_.input_width; }
  const Options& options() const { return options_; }
  /// Width of the features entering the head (the last module's output).
  std::int64_t trunk_width() const { return trunk_width_; }

 private:
  /// One layer of the feature mapping or the head: Linear → tanh → (BatchNorm).
  struct Dense {
    torch::nn::Linear linear{nullptr};
    torch::nn::BatchNorm1d norm{nullptr};
  };
  struct Block {
    std::shared_ptr<graph::GraphOp> op;
    torch::nn::BatchNorm1d norm{nullptr};
  };
  std::vector<Dense> dense_layers(const std::string& name, std::int64_t in,
                                  const std::vector<std::int64_t>& widths);
  Block block(const std::string& name, std::int64_t in);
  torch::Tensor run(std::vector<Dense>& layers, torch::Tensor x);
  torch::Tensor run(Block& b, const torch::Tensor& x, const graph::Graph& graph);

  Options options_;
  std::vector<Dense> features_, head_;
  std::vector<std::vector<Block>> modules_;
  std::vector<Block> transitions_;  ///< transitions_[m] runs after module m (m < modules − 1)
  torch::nn::Linear out_{nullptr};
  std::int64_t trunk_width_ = 0;
};

}  // namespace skinlab::experiments

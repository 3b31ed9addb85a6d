#pragma once
/// \file
/// `b2v`: HeterSkinNet's bone-to-vertex convolution (Pan et al. 2021, Eq. 5 and Fig. 5): each
/// vertex concatenates the features of its K candidate bones, nearest first, to its own,
///
///     f'_v = MLP(f_v ‖ f_{b_{n_v,1}} ‖ ... ‖ f_{b_{n_v,K}})
///
/// where n_v,k = topk_index[v, k] is the k-th nearest bone under the chosen distance (the order
/// fixes which slot of the MLP's input a bone lands in, which is why the candidates are sorted).
/// Updates the vertex features (Fv + K Fb inputs to the MLP); the bone features pass through.
/// The last step of Fig. 3 ("the bone nodes' features are scattered to their neighboring vertex
/// nodes") is this gather; with `mlp: []` it outputs the concatenation for the model's final MLP.
///
///     - {type: b2v, mlp: [256]}
///
/// Options: `mlp` (default [256], the paper's vertex local width; [] outputs the concatenation).
/// Parameters: `mlp.linear<i>.*`.

#include "framework/graph/graph_op.hpp"
#include "framework/graph/mlp.hpp"

namespace skinlab::graph {

class B2v final : public GraphOp {
 public:
  struct Options {
    std::vector<std::int64_t> mlp = {256};
    static Options from(const config::Node& node);
  };
  explicit B2v(Options options) : options_(std::move(options)) {}

  Features forward(const Features& in, const Graph& graph) override;
  std::string type() const override { return "b2v"; }
  const Options& options() const { return options_; }

 protected:
  Dims do_build(const Dims& in) override;

 private:
  Options options_;
  Mlp mlp_{nullptr};
};

}  // namespace skinlab::graph

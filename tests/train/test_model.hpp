#pragma once
// A small learned model for the training tests (registered as `test_vertex_mlp` in
// trainer_test.cpp, so only the train_tests binary has it): per vertex, an MLP over
// [position, 1/D of the K candidates] with dropout and a softmax over the K candidates.

#include <torch/torch.h>

#include "framework/core/config.hpp"
#include "framework/models/model.hpp"

namespace skinlab::testing {

class TestVertexMlp final : public models::Model {
 public:
  struct Options {
    int hidden = 16;
    int top_k = 3;
    double dropout = 0.0;
    static Options from(const config::Node& node) {
      Options o;
      config::Fields f(node, "model 'test_vertex_mlp'");
      f.optional("hidden", o.hidden).check(o.hidden >= 1, "hidden", "must be ≥ 1");
      f.optional("top_k", o.top_k).check(o.top_k >= 1, "top_k", "must be ≥ 1");
      f.optional("dropout", o.dropout)
          .check(o.dropout >= 0 && o.dropout < 1, "dropout", "must be in [0, 1)");
      f.finish();
      return o;
    }
  };

  explicit TestVertexMlp(Options o)
      : options_(o),
        in_(register_module("input", torch::nn::Linear(3 + o.top_k, o.hidden))),
        dropout_(register_module("dropout", torch::nn::Dropout(o.dropout))),
        out_(register_module("output", torch::nn::Linear(o.hidden, o.top_k))) {}

  torch::Tensor forward(const data::CharacterTensors& c) override {
    TORCH_CHECK(c.top_k() == options_.top_k, "test_vertex_mlp: K = ", options_.top_k,
                " but the character has ", c.top_k(), " candidates");
    const torch::Tensor x = torch::cat({c.positions, 1.0 / c.topk_distance.clamp_min(0.05)}, 1);
    const torch::Tensor h = dropout_(torch::leaky_relu(in_(x), 0.2));
    return torch::softmax(out_(h), 1);
  }

 private:
  Options options_;
  torch::nn::Linear in_;
  torch::nn::Dropout dropout_;
  torch::nn::Linear out_;
};

}  // namespace skinlab::testing

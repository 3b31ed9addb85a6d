#include "experiments/densegats/densegats.hpp"

#include <fmt/format.h>

#include "framework/core/registry.hpp"
#include "framework/graph/mlp.hpp"

namespace skinlab::experiments {

namespace {

constexpr const char* kDefaultBlock = "{type: gat_block}";

/// The default block node, parsed once and kept for the life of the program.
config::Node default_block() {
  static const config::Config parsed = config::Config::parse(kDefaultBlock, "densegats default block");
  return parsed.root();
}

void glorot(torch::nn::LinearImpl& linear) {
  torch::NoGradGuard no_grad;
  torch::nn::init::xavier_uniform_(linear.weight);
  if (linear.bias.defined()) linear.bias.zero_();
}

}  // namespace

DenseGats::Options DenseGats::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "model densegats");
  f.optional("input_width", o.input_width).check(o.input_width >= 1, "input_width", "must be ≥ 1");
  f.optional("feature_mlp", o.feature_mlp);
  graph::check_widths(f, "feature_mlp", o.feature_mlp, true);
  f.optional("modules", o.modules).check(o.modules >= 1, "modules", "must be ≥ 1");
  f.optional("blocks_per_module", o.blocks_per_module)
      .check(o.blocks_per_module >= 1, "blocks_per_module", "must be ≥ 1");
  f.optional("dense", o.dense);
  f.optional("transitions", o.transitions);
  o.block = f.section("block");
  f.optional("head", o.head);
  graph::check_widths(f, "head", o.head, true);
  f.optional("batch_norm", o.batch_norm);
  f.finish();
  if (!o.block.exists() || o.block.is_null()) o.block = default_block();
  graph::graph_op_from(o.block);  // an unknown op or option is an error now
  return o;
}

DenseGats::DenseGats(Options options) : options_(std::move(options)) {
  features_ = dense_layers("features", options_.input_width, options_.feature_mlp);
  std::int64_t width = options_.feature_mlp.empty() ? options_.input_width : options_.feature_mlp.back();
  for (int m = 0; m < options_.modules; ++m) {
    std::vector<Block> blocks;
    std::int64_t in = width;
    for (int b = 0; b < options_.blocks_per_module; ++b) {
      blocks.push_back(block(fmt::format("module{}_block{}", m, b), in));
      const std::int64_t out = blocks.back().op->out_dims().vertex;
      in = options_.dense ? in + out : out;
    }
    modules_.push_back(std::move(blocks));
    width = in;
    if (options_.transitions && m + 1 < options_.modules) {
      transitions_.push_back(block(fmt::format("transition{}", m), width));
      width = transitions_.back().op->out_dims().vertex;
    }
  }
  trunk_width_ = width;
  head_ = dense_layers("head", width, options_.head);
  out_ = register_module("out", torch::nn::Linear(options_.head.empty() ? width : options_.head.back(), 3));
  torch::NoGradGuard no_grad;
  out_->weight.zero_();
  out_->bias.zero_();
}

std::vector<DenseGats::Dense> DenseGats::dense_layers(const std::string& name, std::int64_t in,
                                                      const std::vector<std::int64_t>& widths) {
  std::vector<Dense> layers;
  for (std::size_t i = 0; i < widths.size(); ++i) {
    Dense d;
    d.linear = register_module(fmt::format("{}_linear{}", name, i), torch::nn::Linear(in, widths[i]));
    glorot(*d.linear);
    if (options_.batch_norm) {
      d.norm = register_module(fmt::format("{}_norm{}", name, i), torch::nn::BatchNorm1d(widths[i]));
    }
    layers.push_back(d);
    in = widths[i];
  }
  return layers;
}

DenseGats::Block DenseGats::block(const std::string& name, std::int64_t in) {
  Block b;
  b.op = register_module(name, graph::graph_op_from(options_.block));
  const graph::Dims out = b.op->build({in, 0, 0});
  TORCH_CHECK(out.vertex >= 1, "densegats: block '", name, "' (", b.op->type(),
              ") must output vertex features");
  if (options_.batch_norm) {
    b.norm = register_module(name + "_norm", torch::nn::BatchNorm1d(out.vertex));
  }
  return b;
}

torch::Tensor DenseGats::run(std::vector<Dense>& layers, torch::Tensor x) {
  for (Dense& d : layers) {
    x = torch::tanh(d.linear->forward(x));
    if (d.norm) x = d.norm->forward(x);
  }
  return x;
}

torch::Tensor DenseGats::run(Block& b, const torch::Tensor& x, const graph::Graph& graph) {
  torch::Tensor y = b.op->forward({x, torch::Tensor()}, graph).vertex;
  return b.norm ? b.norm->forward(y) : y;
}

torch::Tensor DenseGats::forward(const torch::Tensor& features, const graph::Graph& graph) {
  TORCH_CHECK(features.dim() == 2 && features.size(1) == options_.input_width &&
                  features.size(0) == graph.num_vertices,
              "densegats: expected #V×", options_.input_width, " node attributes for the graph's ",
              graph.num_vertices, " vertices, got ", features.sizes());
  torch::Tensor x = run(features_, features);
  for (std::size_t m = 0; m < modules_.size(); ++m) {
    for (Block& b : modules_[m]) {
      const torch::Tensor y = run(b, x, graph);
      // Eq. 5: a block's output joins everything the module has produced so far.
      x = options_.dense ? torch::cat({y, x}, 1) : y;
    }
    if (m < transitions_.size()) x = run(transitions_[m], x, graph);
  }
  return out_->forward(run(head_, x));
}

}  // namespace skinlab::experiments

SKINLAB_REGISTER(corrective_model, densegats, skinlab::experiments::DenseGats);

#include "experiments/densegats/neuroskinning_net.hpp"

#include "framework/core/registry.hpp"

namespace skinlab::experiments {

namespace {

// NeuroSkinning's Fig. 3 widths, as configs/baselines/neuroskinning.yaml; used for any branch a
// config leaves out. The graph has no bone nodes here, so only vertices are pooled.
constexpr const char* kCorrectiveNeuroSkinningDefaults = R"(
stem:
  - {type: gconv_pool, mlp: [256]}
global: {type: global_pool, pool: [vertex], vertex_mlp: [1024], to: [vertex], keep_input: false}
local:
  - {type: gconv_pool, mlp: [128]}
  - {type: gconv_pool, mlp: [128]}
)";

}  // namespace

NeuroSkinningCorrective::Options NeuroSkinningCorrective::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "corrective model neuroskinning");
  o.read(f);
  f.optional("input_width", o.input_width).check(o.input_width >= 1, "input_width", "must be ≥ 1");
  f.optional("input_mlp", o.input_mlp);
  graph::check_widths(f, "input_mlp", o.input_mlp, true);
  f.finish();
  o.fill_missing_branches(kCorrectiveNeuroSkinningDefaults);
  return o;
}

NeuroSkinningCorrective::NeuroSkinningCorrective(Options options)
    : options_(std::move(options)),
      layers_(*this, "neuroskinning", options_, options_.input_width, options_.input_mlp, 0, 3) {
  torch::NoGradGuard no_grad;
  auto& out = layers_.head()->linear(layers_.head()->options().widths.size() - 1);
  out->weight.zero_();
  out->bias.zero_();
}

torch::Tensor NeuroSkinningCorrective::forward(const torch::Tensor& features,
                                               const graph::Graph& graph) {
  TORCH_CHECK(features.dim() == 2 && features.size(1) == options_.input_width &&
                  features.size(0) == graph.num_vertices,
              "neuroskinning: expected #V×", options_.input_width,
              " node attributes for the graph's ", graph.num_vertices, " vertices, got ",
              features.sizes());
  return layers_.forward(features, torch::Tensor(), graph);
}

}  // namespace skinlab::experiments

SKINLAB_REGISTER(corrective_model, neuroskinning, skinlab::experiments::NeuroSkinningCorrective);

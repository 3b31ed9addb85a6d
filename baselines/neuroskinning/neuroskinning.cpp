#include "baselines/neuroskinning/neuroskinning.hpp"

#include "framework/core/registry.hpp"

namespace skinlab::baselines {

namespace {

// The widths of NeuroSkinning's Fig. 3, for any of `stem`, `local`, `global` a config leaves out.
constexpr const char* kNeuroSkinningDefaults = R"(
stem:
  - {type: gconv_pool, mlp: [256]}
local:
  - {type: gconv_pool, mlp: [128]}
  - {type: gconv_pool, mlp: [128]}
global: {type: global_pool, pool: [vertex], vertex_mlp: [1024], to: [vertex], keep_input: false}
)";

}  // namespace

NeuroSkinning::Options NeuroSkinning::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "model neuroskinning");
  o.read(f);
  f.optional("normals", o.normals);
  f.optional("input_mlp", o.input_mlp);
  for (auto w : o.input_mlp) f.check(w >= 1, "input_mlp", "widths must be ≥ 1");
  f.finish();
  o.fill_missing_branches(kNeuroSkinningDefaults);
  return o;
}

NeuroSkinning::NeuroSkinning(Options options)
    : BranchedNetwork("neuroskinning", options, (options.normals ? 6 : 3) + options.top_k,
                      options.input_mlp),
      options_(std::move(options)) {}

torch::Tensor NeuroSkinning::input_features(const data::CharacterTensors& c) const {
  std::vector<torch::Tensor> parts = {c.positions};
  if (options_.normals) {
    TORCH_CHECK(c.normals.defined() && c.normals.sizes() == c.positions.sizes(),
                "neuroskinning: character '", c.name, "' has no #V×3 vertex normals");
    parts.push_back(c.normals);
  }
  parts.push_back(models::inverse_distance(c.topk_distance, options_));
  return torch::cat(parts, 1);
}

}  // namespace skinlab::baselines

SKINLAB_REGISTER(model, neuroskinning, skinlab::baselines::NeuroSkinning);

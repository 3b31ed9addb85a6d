#include "baselines/rignet_skin/rignet_skin.hpp"

#include "framework/core/registry.hpp"

namespace skinlab::baselines {

namespace {

// RigNet's widths (models/SKINNING.py l. 32–35; GCU(in → out): edge MLPs [out/2, out/2], fusing
// MLP [out], models/gcn_basic_modules.py l. 51–55), for any of `stem`, `local`, `global` that a
// config leaves out.
constexpr const char* kRigNetDefaults = R"(
stem:
  - {type: mesh_conv, edges: [one_ring, geodesic], edge_mlp: [256, 256], mlp: [512]}
local:
  - {type: mesh_conv, edges: [one_ring, geodesic], edge_mlp: [128, 128], mlp: [256]}
  - {type: mesh_conv, edges: [one_ring, geodesic], edge_mlp: [128, 128], mlp: [256]}
global: {type: global_pool, pool: [vertex], vertex_mlp: [512, 1024], to: [vertex], keep_input: false}
)";

}  // namespace

RigNetSkin::Options RigNetSkin::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "model rignet_skin");
  o.read(f);
  f.optional("leaf_flag", o.leaf_flag);
  f.optional("input_mlp", o.input_mlp);
  for (auto w : o.input_mlp) f.check(w >= 1, "input_mlp", "widths must be ≥ 1");
  f.finish();
  o.fill_missing_branches(kRigNetDefaults);
  return o;
}

RigNetSkin::RigNetSkin(Options options)
    : BranchedNetwork("rignet_skin", options, 3 + options.top_k * (options.leaf_flag ? 8 : 7),
                      options.input_mlp),
      options_(std::move(options)) {}

torch::Tensor RigNetSkin::input_features(const data::CharacterTensors& c) const {
  const std::int64_t nv = c.num_vertices(), k = options_.top_k;
  const torch::Tensor flat = c.topk_index.reshape({-1});
  std::vector<torch::Tensor> parts;
  parts.push_back(c.bones.index_select(0, flat).reshape({nv, k, 6}));  // start ‖ end
  parts.push_back(models::inverse_distance(c.topk_distance, options_).reshape({nv, k, 1}));
  if (options_.leaf_flag) {
    // RigNet's virtual leaf bone is our helper bone at a leaf joint: start joint == end joint.
    parts.push_back(models::leaf_candidates(c).reshape({nv, k, 1}));
  }
  return torch::cat({c.positions, torch::cat(parts, 2).reshape({nv, -1})}, 1);
}

}  // namespace skinlab::baselines

SKINLAB_REGISTER(model, rignet_skin, skinlab::baselines::RigNetSkin);

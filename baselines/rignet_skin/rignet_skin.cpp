#include "baselines/rignet_skin/rignet_skin.hpp"

#include "framework/core/registry.hpp"

namespace skinlab::baselines {

namespace {

// RigNet's widths (models/SKINNING.py l. 32–35; GCU(in → out): edge MLPs [out/2, out/2], fusing
// MLP [out], models/gcn_basic_modules.py l. 51–55), for any of `stem`, `local`, `global` that a
// config leaves out.
constexpr const char* kDefaults = R"(
stem:
  - {type: mesh_conv, edges: [one_ring, geodesic], edge_mlp: [256, 256], mlp: [512]}
local:
  - {type: mesh_conv, edges: [one_ring, geodesic], edge_mlp: [128, 128], mlp: [256]}
  - {type: mesh_conv, edges: [one_ring, geodesic], edge_mlp: [128, 128], mlp: [256]}
global: {type: global_pool, pool: [vertex], vertex_mlp: [512, 1024], to: [vertex], keep_input: false}
)";

const config::Config& defaults() {
  static const config::Config c = config::Config::parse(kDefaults);
  return c;
}

}  // namespace

RigNetSkin::Options RigNetSkin::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "model rignet_skin");
  o.read(f);
  f.optional("leaf_flag", o.leaf_flag);
  f.optional("input_mlp", o.input_mlp);
  for (auto w : o.input_mlp) f.check(w >= 1, "input_mlp", "widths must be ≥ 1");
  f.finish();
  o.fill_missing_branches(defaults());
  return o;
}

RigNetSkin::RigNetSkin(Options options) : options_(std::move(options)) {
  const std::int64_t k = options_.top_k;
  const std::int64_t in_width = 3 + k * (options_.leaf_flag ? 8 : 7);
  input_ = register_module("input", graph::Mlp(in_width, graph::MlpOptions{options_.input_mlp}));
  stem_ = register_module("stem", graph::Sequence::from(options_.stem));
  local_ = register_module("local", graph::Sequence::from(options_.local));
  // "global" is a Python keyword: libtorch checkpoints cannot store it as a module name.
  global_ = register_module("global_branch", graph::graph_op_from(options_.global));
  // The bone attributes ride along (width 6) so a config may add skeleton ops; RigNet uses none.
  const graph::Dims in{input_->out_width(), 6, k};
  const graph::Dims x = stem_->build(in);
  const graph::Dims g = global_->build(x);
  const graph::Dims l = local_->build(x);
  TORCH_CHECK(l.vertex >= 1, "rignet_skin: the local branch must end with vertex features");
  TORCH_CHECK(g.vertex >= 1, "rignet_skin: the global branch must give the vertices a feature");
  graph::MlpOptions head;
  head.widths = options_.head;
  head.widths.push_back(k);
  head.activate_last = false;
  head.dropout = options_.head_dropout;
  head_ = register_module("head", graph::Mlp(l.vertex + g.vertex, std::move(head)));
}

torch::Tensor RigNetSkin::input_features(const data::CharacterTensors& c) const {
  const std::int64_t nv = c.num_vertices(), k = options_.top_k;
  const torch::Tensor flat = c.topk_index.reshape({-1});
  std::vector<torch::Tensor> parts;
  parts.push_back(c.bones.index_select(0, flat).reshape({nv, k, 6}));  // start ‖ end
  parts.push_back(models::inverse_distance(c.topk_distance, options_).reshape({nv, k, 1}));
  if (options_.leaf_flag) {
    // RigNet's virtual leaf bone is our helper bone at a leaf joint: start joint == end joint.
    const torch::Tensor leaf =
        (c.bone_joints.select(1, 0) == c.bone_joints.select(1, 1)).to(c.positions.scalar_type());
    parts.push_back(leaf.index_select(0, flat).reshape({nv, k, 1}));
  }
  return torch::cat({c.positions, torch::cat(parts, 2).reshape({nv, -1})}, 1);
}

torch::Tensor RigNetSkin::forward(const data::CharacterTensors& c) {
  TORCH_CHECK(c.top_k() == options_.top_k, "rignet_skin: built for top_k = ", options_.top_k,
              " but character '", c.name, "' has ", c.top_k(),
              " candidate bones per vertex (set model.top_k to the dataset's top_k)");
  const graph::Graph g = graph::make_graph(c);
  graph::Features in;
  in.vertex = input_->forward(input_features(c));
  in.bone = c.bones;
  const graph::Features x = stem_->forward(in, g);
  const graph::Features glob = global_->forward(x, g);
  const graph::Features loc = local_->forward(x, g);
  return torch::softmax(head_->forward(torch::cat({loc.vertex, glob.vertex}, 1)), 1);
}

}  // namespace skinlab::baselines

SKINLAB_REGISTER(model, rignet_skin, skinlab::baselines::RigNetSkin);

#include "experiments/heterskinnet/heterskinnet.hpp"

#include "framework/core/registry.hpp"
#include "framework/tensors/candidates.hpp"

namespace skinlab::experiments {

namespace {

// The paper's architecture (Sec. 3.3, 4.2) as config text, used for any of `stem`, `local`,
// `global` that a config leaves out.
constexpr const char* kHeterSkinNetDefaults = R"(
stem:
  - {type: b2v, mlp: [256]}
  - {type: v2b, mlp: [128]}
  - {type: mesh_conv, edge_mlp: [256], mlp: [256]}
  - {type: edge_conv, edges: skeleton, mlp: [128]}
local:
  - {type: b2v, mlp: [256]}
  - {type: v2b, mlp: [128]}
  - {type: mesh_conv, edge_mlp: [256], mlp: [256]}
  - {type: edge_conv, edges: skeleton, mlp: [128]}
  - {type: b2v, mlp: [256]}
  - {type: v2b, mlp: [128]}
  - {type: mesh_conv, edge_mlp: [256], mlp: [256]}
  - {type: edge_conv, edges: skeleton, mlp: [128]}
global: {type: global_pool, vertex_mlp: [512], bone_mlp: [512], to: [vertex], keep_input: false}
)";

}  // namespace

HeterSkinNet::Options HeterSkinNet::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "model heterskinnet");
  o.BranchedModelOptions::read(f);
  o.PriorOptions::read(f);
  o.edge_dropout = graph::EdgeDropoutOptions::from(f.section("edge_dropout"));
  f.finish();
  o.fill_missing_branches(kHeterSkinNetDefaults);
  return o;
}

HeterSkinNet::HeterSkinNet(Options options) : options_(std::move(options)) {
  stem_ = register_module("stem", graph::Sequence::from(options_.stem));
  local_ = register_module("local", graph::Sequence::from(options_.local));
  global_ = register_module(
      "global_branch",
      graph::graph_op_from(
          options_.global));  // "global" is a Python keyword: libtorch checkpoints cannot store it
  const std::int64_t prior_inputs = options_.prior.empty() ? 0 : options_.top_k;
  const graph::Dims in{options_.top_k + 3 + prior_inputs, 6, options_.top_k};
  const graph::Dims x = stem_->build(in);
  const graph::Dims g = global_->build(x);
  const graph::Dims l = local_->build(x);
  TORCH_CHECK(l.vertex >= 1 && l.bone >= 1,
              "heterskinnet: the local branch must end with vertex and bone features, got widths ",
              l.vertex, " and ", l.bone);
  graph::MlpOptions head;
  head.widths = options_.head;
  head.widths.push_back(options_.top_k);
  head.activate_last = false;
  head.dropout = options_.head_dropout;
  head_ = register_module(
      "head", graph::Mlp(l.vertex + options_.top_k * l.bone + g.vertex, std::move(head)));
}

torch::Tensor HeterSkinNet::forward(const data::CharacterTensors& character) {
  // A character with fewer bones than K has only that many candidates: they are padded to K
  // and the padded slots are dropped from the head's logits before the softmax
  // (data::candidates_for_model), so the weights are over its own candidates (#V×its K).
  const std::int64_t k_own = character.top_k();
  const data::CharacterTensors c =
      data::candidates_for_model(character, options_.top_k, "heterskinnet");
  const std::int64_t nv = c.num_vertices(), k = options_.top_k;
  graph::Graph g = graph::make_graph(c);
  if (is_training() && options_.edge_dropout.p > 0) g = graph::drop_edges(g, options_.edge_dropout);

  torch::Tensor prior;  // #V×K, the prior's weight on each candidate
  if (!options_.prior.empty()) prior = data::prior_of(c, options_.prior, "heterskinnet");

  std::vector<torch::Tensor> vertex_inputs{
      c.positions, models::inverse_distance(c.topk_distance, options_)};
  if (prior.defined()) vertex_inputs.push_back(prior);
  graph::Features in;
  in.vertex = torch::cat(vertex_inputs, 1);
  in.bone = c.bones;
  const graph::Features x = stem_->forward(in, g);
  const graph::Features glob = global_->forward(x, g);
  const graph::Features loc = local_->forward(x, g);
  // The head's input is [local vertex ‖ its K candidates' local bone features ‖ global]; the
  // global part is one row broadcast to all vertices when global_pool does not keep its input.
  const bool broadcast = glob.vertex.size(0) == nv && glob.vertex.stride(0) == 0;
  torch::Tensor logits;
  if (broadcast) {
    logits =
        head_->forward_gathered(loc.vertex, loc.bone, c.topk_index, glob.vertex.narrow(0, 0, 1));
  } else {
    const torch::Tensor candidates =
        loc.bone.index_select(0, c.topk_index.reshape({-1})).reshape({nv, k * loc.bone.size(1)});
    logits = head_->forward(torch::cat({loc.vertex, candidates, glob.vertex}, 1));
  }
  if (prior.defined() && options_.prior_bias) {
    logits = logits + torch::log(prior + options_.prior_epsilon);
  }
  logits = models::with_leaf_bias(logits, c, options_.leaf_bias, is_training());
  return torch::softmax(logits.narrow(1, 0, k_own), 1);
}

}  // namespace skinlab::experiments

SKINLAB_REGISTER(model, heterskinnet, skinlab::experiments::HeterSkinNet);

#include "framework/models/branched_model.hpp"

#include <cmath>
#include <map>
#include <mutex>

#include "framework/tensors/candidates.hpp"

namespace skinlab::models {

void BranchedModelOptions::read(config::Fields& f) {
  f.optional("top_k", top_k);
  f.optional("distance_unit", distance_unit);
  f.optional("min_distance", min_distance);
  stem = f.section("stem");
  local = f.section("local");
  global = f.section("global");
  f.optional("head", head);
  f.optional("head_dropout", head_dropout);
  f.optional("leaf_bias", leaf_bias);
  f.check(top_k >= 1, "top_k", "must be ≥ 1");
  f.check(distance_unit > 0, "distance_unit", "must be positive");
  f.check(min_distance > 0, "min_distance", "must be positive");
  for (auto w : head) f.check(w >= 1, "head", "widths must be ≥ 1");
  f.check(head_dropout >= 0 && head_dropout < 1, "head_dropout", "must be in [0, 1)");
  f.check(std::isfinite(leaf_bias), "leaf_bias", "must be finite");
}

void PriorOptions::read(config::Fields& f) {
  const bool bias_given = f.section("prior_bias").exists();
  f.optional("prior", prior);
  f.optional("prior_bias", prior_bias);
  f.optional("prior_epsilon", prior_epsilon);
  f.optional("keep_prior_outside", keep_prior_outside);
  f.optional("prior_mix", prior_mix);
  f.check(prior_epsilon > 0, "prior_epsilon", "must be positive");
  f.check(!prior_bias || !prior.empty() || !bias_given, "prior_bias", "needs a `prior`");
  f.check(!keep_prior_outside || !prior.empty(), "keep_prior_outside", "needs a `prior`");
  f.check(prior_mix >= 0 && prior_mix <= 1, "prior_mix", "must be in [0, 1]");
  f.check(prior_mix == 0 || !prior.empty(), "prior_mix", "needs a `prior`");
}

PriorOptions PriorOptions::of(const config::Node& model) {
  PriorOptions prior;
  config::Fields fields(model, "model " + model["type"].as<std::string>());
  prior.read(fields);
  return prior;
}

void BranchedModelOptions::fill_missing_branches(const char* defaults_yaml) {
  static std::mutex mutex;
  static std::map<const char*, config::Config> parsed;
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = parsed.find(defaults_yaml);
  if (it == parsed.end()) {
    it = parsed.emplace(defaults_yaml, config::Config::parse(defaults_yaml)).first;
  }
  const config::Node root = it->second.root();
  if (!stem.exists()) stem = root["stem"];
  if (!local.exists()) local = root["local"];
  if (!global.exists()) global = root["global"];
}

torch::Tensor leaf_candidates(const data::CharacterTensors& c) {
  const torch::Tensor leaf_bone = c.bone_joints.select(1, 0) == c.bone_joints.select(1, 1);
  return leaf_bone.index_select(0, c.topk_index.reshape({-1}))
      .reshape(c.topk_index.sizes())
      .to(torch::kFloat32);
}

torch::Tensor with_leaf_bias(const torch::Tensor& logits, const data::CharacterTensors& c,
                             double leaf_bias, bool training) {
  if (training || leaf_bias == 0) return logits;
  return logits + leaf_bias * leaf_candidates(c);
}

torch::Tensor inverse_distance(const torch::Tensor& topk_distance,
                               const BranchedModelOptions& options) {
  return (topk_distance / options.distance_unit).clamp_min(options.min_distance).reciprocal();
}

BranchedLayers::BranchedLayers(torch::nn::Module& owner, const std::string& name,
                               const BranchedModelOptions& options, std::int64_t input_width,
                               const std::vector<std::int64_t>& input_mlp, std::int64_t bone_width,
                               std::int64_t outputs) {
  input_ = owner.register_module("input", graph::Mlp(input_width, graph::MlpOptions{input_mlp}));
  stem_ = owner.register_module("stem", graph::Sequence::from(options.stem));
  local_ = owner.register_module("local", graph::Sequence::from(options.local));
  global_ = owner.register_module("global_branch", graph::graph_op_from(options.global));
  const graph::Dims in{input_->out_width(), bone_width, options.top_k};
  const graph::Dims x = stem_->build(in);
  const graph::Dims g = global_->build(x);
  const graph::Dims l = local_->build(x);
  TORCH_CHECK(l.vertex >= 1, name, ": the local branch must end with vertex features");
  TORCH_CHECK(g.vertex >= 1, name, ": the global branch must give the vertices a feature");
  graph::MlpOptions head;
  head.widths = options.head;
  head.widths.push_back(outputs);
  head.activate_last = false;
  head.dropout = options.head_dropout;
  head_ = owner.register_module("head", graph::Mlp(l.vertex + g.vertex, std::move(head)));
}

torch::Tensor BranchedLayers::forward(const torch::Tensor& features, const torch::Tensor& bones,
                                      const graph::Graph& graph) {
  graph::Features in;
  in.vertex = input_->forward(features);
  in.bone = bones;
  const graph::Features x = stem_->forward(in, graph);
  const graph::Features glob = global_->forward(x, graph);
  const graph::Features loc = local_->forward(x, graph);
  // A global branch that gives every vertex one broadcast row (global_pool without keep_input,
  // stride 0) enters the head's layer 0 as a shared row (Mlp::forward_gathered, no candidate
  // blocks): the same map as the concatenation, without #V copies of the row in the product.
  if (glob.vertex.size(0) > 0 && glob.vertex.stride(0) == 0) {
    return head_->forward_gathered(loc.vertex, torch::empty({0, 0}, loc.vertex.options()),
                                   torch::empty({loc.vertex.size(0), 0}, torch::kInt64),
                                   glob.vertex.narrow(0, 0, 1));
  }
  return head_->forward(torch::cat({loc.vertex, glob.vertex}, 1));
}

BranchedNetwork::BranchedNetwork(std::string name, const BranchedModelOptions& options,
                                 std::int64_t input_width,
                                 const std::vector<std::int64_t>& input_mlp)
    : name_(std::move(name)),
      top_k_(options.top_k),
      leaf_bias_(options.leaf_bias),
      layers_(*this, name_, options, input_width, input_mlp, 6, options.top_k) {}

torch::Tensor BranchedNetwork::forward(const data::CharacterTensors& character) {
  // A character with fewer bones than K: its candidates padded to K, the padded slots' logits
  // dropped before the softmax (data::candidates_for_model), as HeterSkinNet does.
  const data::CharacterTensors c = data::candidates_for_model(character, top_k_, name_);
  const torch::Tensor logits =
      with_leaf_bias(layers_.forward(input_features(c), c.bones, graph::make_graph(c)), c,
                     leaf_bias_, is_training());
  return torch::softmax(logits.narrow(1, 0, character.top_k()), 1);
}

}  // namespace skinlab::models

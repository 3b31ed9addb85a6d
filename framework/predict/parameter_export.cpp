#include "framework/predict/parameter_export.hpp"

#include "framework/graph/b2v.hpp"
#include "framework/graph/edge_conv.hpp"
#include "framework/graph/global_pool.hpp"
#include "framework/graph/graph_op.hpp"
#include "framework/graph/mesh_conv.hpp"
#include "framework/graph/mlp.hpp"
#include "framework/graph/v2b.hpp"
#include "framework/models/branched_model.hpp"

namespace skinlab::predict {

namespace {

using Json = nlohmann::json;

Json node_names(const std::vector<graph::GlobalPool::Node>& nodes) {
  Json out = Json::array();
  for (auto n : nodes) out.push_back(n == graph::GlobalPool::Node::kVertex ? "vertex" : "bone");
  return out;
}

/// `op`'s type and the options its forward pass needs; the type only for an op the Eigen
/// forward pass does not implement.
Json describe(const graph::GraphOp& op) {
  Json d = {{"type", op.type()}};
  if (const auto* b2v = dynamic_cast<const graph::B2v*>(&op)) {
    d["mlp"] = b2v->options().mlp;
  } else if (const auto* v2b = dynamic_cast<const graph::V2b*>(&op)) {
    d["mlp"] = v2b->options().mlp;
    d["variance_scale"] = v2b->options().variance_scale;
  } else if (const auto* edge = dynamic_cast<const graph::EdgeConv*>(&op)) {
    d["edges"] = graph::to_string(edge->options().edges);
    d["mlp"] = edge->options().mlp;
    d["self_loops"] = edge->options().self_loops;
  } else if (const auto* mesh = dynamic_cast<const graph::MeshConv*>(&op)) {
    Json sets = Json::array();
    for (auto set : mesh->options().edges) sets.push_back(graph::to_string(set));
    d["edges"] = sets;
    d["edge_mlp"] = mesh->options().edge_mlp;
    d["mlp"] = mesh->options().mlp;
    d["self_loops"] = mesh->options().self_loops;
  } else if (const auto* pool = dynamic_cast<const graph::GlobalPool*>(&op)) {
    const auto& o = pool->options();
    d["pool"] = node_names(o.pool);
    d["vertex_mlp"] = o.vertex_mlp;
    d["bone_mlp"] = o.bone_mlp;
    d["order"] = o.mlp_first ? "mlp_max" : "max_mlp";
    d["to"] = node_names(o.to);
    d["keep_input"] = o.keep_input;
  }
  return d;
}

}  // namespace

infer::ParameterFile parameter_file(const models::Model& model, const train::RunOptions& run,
                                    const std::string& source) {
  infer::ParameterFile p;
  p.model = run.model["type"].as<std::string>();
  p.distance = run.data.distance;
  p.source = source;
  models::BranchedModelOptions options;  // the defaults for a model without these fields
  {
    config::Fields fields(run.model, "model " + p.model);
    options.read(fields);
  }
  Json& a = p.architecture;
  a["top_k"] = options.top_k;
  a["distance_unit"] = options.distance_unit;
  a["min_distance"] = options.min_distance;
  if (options.leaf_bias != 0) a["leaf_bias"] = options.leaf_bias;
  if (const models::PriorOptions prior = models::PriorOptions::of(run.model); !prior.prior.empty()) {
    a["prior"] = prior.prior;
    a["prior_bias"] = prior.prior_bias;
    a["prior_epsilon"] = prior.prior_epsilon;
    a["keep_prior_outside"] = prior.keep_prior_outside;
    if (prior.prior_mix != 0) a["prior_mix"] = prior.prior_mix;
  }
  for (const auto& child : model.named_children()) {
    if (const auto* sequence = dynamic_cast<const graph::Sequence*>(child.value().get())) {
      Json ops = Json::array();
      const auto names = sequence->named_children();
      for (std::size_t i = 0; i < sequence->ops().size(); ++i) {
        Json d = describe(*sequence->ops()[i]);
        d["name"] = names[i].key();
        ops.push_back(d);
      }
      a[child.key()] = ops;
    } else if (const auto* op = dynamic_cast<const graph::GraphOp*>(child.value().get())) {
      Json d = describe(*op);
      d["name"] = child.key();
      a[child.key()] = d;
    }
  }
  Json mlps = Json::object();
  for (const auto& item : model.named_modules("", /*include_self=*/false)) {
    if (const auto* mlp = dynamic_cast<const graph::MlpImpl*>(item.value().get())) {
      mlps[item.key()] = {{"in", mlp->in_width()},
                          {"widths", mlp->options().widths},
                          {"activate_last", mlp->options().activate_last}};
    }
  }
  a["mlps"] = mlps;
  for (const auto& item : model.named_parameters(/*recurse=*/true)) {
    const torch::Tensor t = item.value().detach().to(torch::kFloat32).contiguous();
    infer::ParameterArray array;
    array.shape.assign(t.sizes().begin(), t.sizes().end());
    array.values.assign(t.data_ptr<float>(), t.data_ptr<float>() + t.numel());
    p.parameters.emplace(item.key(), std::move(array));
  }
  return p;
}

void write_parameter_file(const std::filesystem::path& file, const models::Model& model,
                          const train::RunOptions& run, const std::string& source) {
  infer::write_parameter_file(file, parameter_file(model, run, source));
}

}  // namespace skinlab::predict

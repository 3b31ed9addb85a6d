#include "framework/graph/mesh_conv.hpp"

#include "framework/core/registry.hpp"
#include "framework/graph/aggregate.hpp"

namespace skinlab::graph {

MeshConv::Options MeshConv::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "graph_op 'mesh_conv'");
  const config::Node sets = f.section("edges");
  if (sets.exists()) {
    if (!sets.is_sequence() || sets.size() == 0) {
      sets.fail("expected a non-empty list of mesh edge sets, e.g. [one_ring, geodesic]");
    }
    o.edges.clear();
    for (std::size_t i = 0; i < sets.size(); ++i) {
      const EdgeSet set = parse_edge_set(sets[i]);
      if (is_bone_set(set)) sets[i].fail("mesh_conv runs on vertex edge sets (one_ring, geodesic)");
      for (EdgeSet seen : o.edges) {
        if (seen == set)
          sets[i].fail(std::string("edge set '") + to_string(set) + "' listed twice");
      }
      o.edges.push_back(set);
    }
  }
  f.optional("edge_mlp", o.edge_mlp);
  check_widths(f, "edge_mlp", o.edge_mlp, /*allow_empty=*/false);
  f.optional("mlp", o.mlp);
  check_widths(f, "mlp", o.mlp, /*allow_empty=*/true);
  f.optional("self_loops", o.self_loops);
  f.finish();
  return o;
}

Dims MeshConv::do_build(const Dims& in) {
  TORCH_CHECK(in.vertex >= 1, type(), ": needs vertex features, but their input width is 0");
  std::int64_t concatenated = 0;
  for (EdgeSet set : options_.edges) {
    edge_mlps_.push_back(register_module(std::string("edge_mlp_") + to_string(set),
                                         Mlp(2 * in.vertex, MlpOptions{options_.edge_mlp})));
    concatenated += edge_mlps_.back()->out_width();
  }
  mlp_ = register_module("mlp", Mlp(concatenated, MlpOptions{options_.mlp}));
  Dims out = in;
  out.vertex = mlp_->out_width();
  return out;
}

Features MeshConv::forward(const Features& in, const Graph& graph) {
  check_built();
  check_features(in.vertex, graph.num_vertices, in_dims().vertex, "vertex features", type());
  std::vector<torch::Tensor> branches;
  for (std::size_t s = 0; s < options_.edges.size(); ++s) {
    const EdgeSet set = options_.edges[s];
    check_edges(graph.edges(set), graph.num_vertices, to_string(set), "vertices", type());
    branches.push_back(
        edge_conv_max(in.vertex, graph.edges(set), *edge_mlps_[s], options_.self_loops));
  }
  Features out = in;
  out.vertex = mlp_->forward(branches.size() == 1 ? branches[0] : torch::cat(branches, 1));
  return out;
}

}  // namespace skinlab::graph

SKINLAB_REGISTER(graph_op, mesh_conv, skinlab::graph::MeshConv);

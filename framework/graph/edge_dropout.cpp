#include "framework/graph/edge_dropout.hpp"

namespace skinlab::graph {

EdgeDropoutOptions EdgeDropoutOptions::from(const config::Node& node) {
  EdgeDropoutOptions o;
  config::Fields f(node, "edge_dropout", {});
  f.optional("p", o.p).check(o.p >= 0 && o.p <= 1, "p", "must be a probability in [0, 1]");
  f.optional("symmetric", o.symmetric);
  const config::Node sets = f.section("edges");
  if (sets.exists()) {
    if (!sets.is_sequence()) sets.fail("expected a list of edge sets, e.g. [one_ring, geodesic]");
    o.edges.clear();
    for (std::size_t i = 0; i < sets.size(); ++i) {
      const EdgeSet set = parse_edge_set(sets[i]);
      for (EdgeSet seen : o.edges) {
        if (seen == set)
          sets[i].fail(std::string("edge set '") + to_string(set) + "' listed twice");
      }
      o.edges.push_back(set);
    }
  }
  f.finish();
  return o;
}

torch::Tensor drop_edges(const torch::Tensor& edges, double p, bool symmetric) {
  TORCH_CHECK(p >= 0 && p <= 1, "drop_edges: p must be in [0, 1], got ", p);
  TORCH_CHECK(edges.defined() && edges.dim() == 2 && edges.size(1) == 2,
              "drop_edges: edges must be #E×2, got shape ",
              edges.defined() ? edges.sizes() : c10::IntArrayRef{});
  if (p == 0 || edges.size(0) == 0) return edges;
  torch::Tensor keep;
  if (symmetric) {
    const torch::Tensor lo = std::get<0>(edges.min(1)), hi = std::get<0>(edges.max(1));
    const std::int64_t stride = hi.max().item<std::int64_t>() + 1;
    const auto [pairs, pair_of_edge] = torch::_unique(lo * stride + hi, /*sorted=*/false,
                                                      /*return_inverse=*/true);
    keep = (torch::rand({pairs.size(0)}, torch::kFloat64) >= p).index_select(0, pair_of_edge);
  } else {
    keep = torch::rand({edges.size(0)}, torch::kFloat64) >= p;
  }
  return edges.index_select(0, keep.nonzero().view(-1));
}

Graph drop_edges(const Graph& graph, const EdgeDropoutOptions& options) {
  Graph out = graph;
  for (EdgeSet set : options.edges) {
    const torch::Tensor& e = graph.edges(set);
    if (!e.defined()) continue;
    torch::Tensor kept = drop_edges(e, options.p, options.symmetric);
    switch (set) {
      case EdgeSet::kOneRing:
        out.one_ring = kept;
        break;
      case EdgeSet::kGeodesic:
        out.geodesic = kept;
        break;
      case EdgeSet::kSkeleton:
        out.skeleton = kept;
        break;
    }
  }
  return out;
}

}  // namespace skinlab::graph

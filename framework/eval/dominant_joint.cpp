#include "framework/eval/dominant_joint.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include "framework/core/registry.hpp"
#include "framework/eval/value_display.hpp"
#include "framework/eval/weights.hpp"

namespace skinlab::eval {

DominantJoint::Options DominantJoint::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "metric 'dominant_joint'");
  f.optional("prune", o.prune).check(o.prune >= 0 && o.prune <= 1, "prune", "must be in [0, 1]");
  f.finish();
  return o;
}

namespace {

/// Per row of W (#V×#J): the column of the largest weight (lower index on ties), −1 for a row
/// without a positive weight.
std::vector<int> dominant_columns(const geometry::SparseWeights& W) {
  std::vector<int> out(static_cast<std::size_t>(W.rows()), -1);
  for (Eigen::Index v = 0; v < W.outerSize(); ++v) {
    double best = 0;
    for (geometry::SparseWeights::InnerIterator it(W, v); it; ++it) {
      if (it.value() > best) {  // columns ascend, so a tie keeps the lower index
        best = it.value();
        out[static_cast<std::size_t>(v)] = static_cast<int>(it.col());
      }
    }
  }
  return out;
}

}  // namespace

std::map<std::string, double> DominantJoint::operator()(const MetricInputs& in) const {
  TORCH_CHECK(in.character != nullptr, error_context(in, "dominant_joint"),
              ": needs the prepared character (its skeleton)");
  auto [P, G] = read_weights(in, "dominant_joint");
  prune_rows(P, options_.prune);
  const data::PreparedCharacter& c = *in.character;
  const int nj = c.num_joints();
  const std::vector<int> pred = dominant_columns(joint_weights(P, c.bones, nj));
  const std::vector<int> truth = dominant_columns(joint_weights(G, c.bones, nj));
  std::vector<int> children(static_cast<std::size_t>(nj), 0);
  for (int p : c.parents) {
    if (p >= 0) ++children[static_cast<std::size_t>(p)];
  }
  long weighted = 0, agree = 0, leaf = 0, to_parent = 0;
  for (std::size_t v = 0; v < truth.size(); ++v) {
    const int t = truth[v];
    if (t < 0) continue;
    ++weighted;
    agree += pred[v] == t;
    if (children[static_cast<std::size_t>(t)] == 0 && c.parents[t] >= 0) {
      ++leaf;
      to_parent += pred[v] == c.parents[t];
    }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {{"dominant_joint", weighted > 0 ? static_cast<double>(agree) / weighted : nan},
          {"leaf_to_parent", leaf > 0 ? static_cast<double>(to_parent) / leaf : nan}};
}

}  // namespace skinlab::eval

SKINLAB_DECLARE_VALUE({"dominant_joint", "Dominant joint", "", true, true, 2});
SKINLAB_DECLARE_VALUE({"leaf_to_parent", "Leaf → parent", "", false, true, 2});
SKINLAB_REGISTER(metric, dominant_joint, skinlab::eval::DominantJoint);

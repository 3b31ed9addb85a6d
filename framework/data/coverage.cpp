#include "framework/data/coverage.hpp"

#include <algorithm>
#include <numeric>

#include "framework/core/error.hpp"
#include "framework/data/preprocess.hpp"

namespace skinlab::data {

double Coverage::entry_share(int k) const {
  return entries > 0 ? static_cast<double>(entries_within.at(k - 1)) / entries : 0.0;
}

double Coverage::weight_share(int k) const {
  return weight > 0 ? weight_within.at(k - 1) / weight : 0.0;
}

void Coverage::add(const Coverage& o) {
  if (max_k == 0 && entries == 0 && vertices == 0) {
    *this = o;
    return;
  }
  if (o.max_k != max_k || o.diagnose_k != diagnose_k) {
    throw Error("Coverage::add: K ranges differ (" + std::to_string(max_k) + "/" +
                std::to_string(diagnose_k) + " and " + std::to_string(o.max_k) + "/" +
                std::to_string(o.diagnose_k) + ")");
  }
  for (int k = 0; k < max_k; ++k) {
    weight_within[k] += o.weight_within[k];
    entries_within[k] += o.entries_within[k];
  }
  weight += o.weight;
  entries += o.entries;
  vertices += o.vertices;
  missed += o.missed;
  missed_helper += o.missed_helper;
  missed_tied += o.missed_tied;
  slots += o.slots;
  weightless_slots += o.weightless_slots;
}

Coverage candidate_coverage(const PreparedCharacter& c, const std::string& distance, int max_k,
                            int diagnose_k) {
  if (max_k < 1 || diagnose_k < 1 || diagnose_k > max_k) {
    throw Error("candidate coverage: need 1 ≤ diagnose_k (" + std::to_string(diagnose_k) +
                ") ≤ max_k (" + std::to_string(max_k) + ")");
  }
  const auto it = c.distances.find(distance);
  if (it == c.distances.end()) {
    throw Error(c.name + ": no stored distance '" + distance + "'");
  }
  if (c.weights.rows() == 0) throw Error(c.name + ": no artist weights");
  const geometry::Skeleton skeleton = c.rig();
  const Eigen::MatrixXd D = it->second.D.cast<double>();
  const Eigen::MatrixXd W = bone_weights(c.weights, skeleton, D);
  const int nb = static_cast<int>(D.cols());

  std::vector<bool> weightless(static_cast<std::size_t>(nb), false);
  {
    const Eigen::VectorXd joint_mass =
        c.weights.transpose() * Eigen::VectorXd::Ones(c.weights.rows());
    for (int b = 0; b < nb; ++b) weightless[b] = joint_mass(c.bones(b, 0)) <= 0;
  }
  std::vector<bool> helper(static_cast<std::size_t>(nb));
  for (int b = 0; b < nb; ++b) helper[b] = c.bones(b, 0) == c.bones(b, 1);

  Coverage out;
  out.max_k = max_k;
  out.diagnose_k = diagnose_k;
  out.weight_within.assign(static_cast<std::size_t>(max_k), 0.0);
  out.entries_within.assign(static_cast<std::size_t>(max_k), 0);
  out.vertices = D.rows();
  std::vector<int> order(static_cast<std::size_t>(nb));
  for (Eigen::Index v = 0; v < D.rows(); ++v) {
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return D(v, a) != D(v, b) ? D(v, a) < D(v, b) : a < b; });
    const int slots = std::min(diagnose_k, nb);
    out.slots += slots;
    for (int r = 0; r < slots; ++r) out.weightless_slots += weightless[order[r]];
    const double kth = D(v, order[slots - 1]);
    for (int r = 0; r < nb; ++r) {
      const int b = order[r];
      const double w = W(v, b);
      if (w <= 0) continue;
      const bool influential = w > kInfluential;
      out.weight += w;
      out.entries += influential;
      for (int k = r; k < max_k; ++k) {  // rank r is within every K > r
        out.weight_within[k] += w;
        out.entries_within[k] += influential;
      }
      if (influential && r >= diagnose_k) {
        ++out.missed;
        out.missed_helper += helper[b];
        out.missed_tied += D(v, b) == kth;
      }
    }
  }
  return out;
}

}  // namespace skinlab::data

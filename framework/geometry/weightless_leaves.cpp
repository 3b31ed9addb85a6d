#include "framework/geometry/weightless_leaves.hpp"

#include <cmath>
#include <vector>

namespace skinlab::geometry {

std::vector<int> drop_weightless_leaves(Character& character) {
  Skeleton& s = character.skeleton;
  const int n = s.num_joints();
  std::vector<double> mass(static_cast<std::size_t>(n), 0.0);
  for (int v = 0; v < character.weights.outerSize(); ++v) {
    for (SparseWeights::InnerIterator it(character.weights, v); it; ++it) {
      mass[static_cast<std::size_t>(it.col())] += std::abs(it.value());
    }
  }
  std::vector<int> children(static_cast<std::size_t>(n), 0);
  for (int j = 0; j < n; ++j) {
    if (s.parents[j] >= 0) ++children[static_cast<std::size_t>(s.parents[j])];
  }
  std::vector<bool> removed(static_cast<std::size_t>(n), false);
  int count = 0;
  for (bool changed = true; changed;) {
    changed = false;
    for (int j = 0; j < n; ++j) {
      const auto u = static_cast<std::size_t>(j);
      if (removed[u] || s.parents[j] < 0 || children[u] > 0 || mass[u] > 0) continue;
      removed[u] = true;
      --children[static_cast<std::size_t>(s.parents[j])];
      ++count;
      changed = true;
    }
  }
  std::vector<int> kept_joints;
  for (int j = 0; j < n; ++j) {
    if (!removed[static_cast<std::size_t>(j)]) kept_joints.push_back(j);
  }
  if (count == 0) return kept_joints;

  std::vector<int> new_index(static_cast<std::size_t>(n), -1);
  Skeleton kept;
  const int m = n - count;
  kept.positions.resize(m, 3);
  if (s.leaf_tips.rows() > 0) kept.leaf_tips.resize(m, 3);
  for (int j = 0, k = 0; j < n; ++j) {
    if (removed[static_cast<std::size_t>(j)]) continue;
    new_index[static_cast<std::size_t>(j)] = k;
    kept.names.push_back(s.names[j]);
    kept.positions.row(k) = s.positions.row(j);
    if (s.leaf_tips.rows() > 0) kept.leaf_tips.row(k) = s.leaf_tips.row(j);
    ++k;
  }
  for (int j = 0; j < n; ++j) {
    if (removed[static_cast<std::size_t>(j)]) continue;
    const int p = s.parents[j];
    kept.parents.push_back(p < 0 ? -1 : new_index[static_cast<std::size_t>(p)]);
  }
  SparseWeights W(character.weights.rows(), m);
  std::vector<Eigen::Triplet<double>> triplets;
  for (int v = 0; v < character.weights.outerSize(); ++v) {
    for (SparseWeights::InnerIterator it(character.weights, v); it; ++it) {
      triplets.emplace_back(v, new_index[static_cast<std::size_t>(it.col())], it.value());
    }
  }
  W.setFromTriplets(triplets.begin(), triplets.end());
  W.makeCompressed();
  s = std::move(kept);
  character.weights = std::move(W);
  return kept_joints;
}

}  // namespace skinlab::geometry

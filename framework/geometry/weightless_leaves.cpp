#include "framework/geometry/weightless_leaves.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace skinlab::geometry {

std::vector<int> drop_leaves(Character& character, const std::function<bool(int)>& removable) {
  Skeleton& s = character.skeleton;
  const int n = s.num_joints();
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
      if (removed[u] || s.parents[j] < 0 || children[u] > 0 || !removable(j)) continue;
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
  if (character.has_weights()) {
    character.weights = onto_kept_joints(character.weights, s.parents, kept_joints);
  }
  s = std::move(kept);
  return kept_joints;
}

std::vector<int> drop_weightless_leaves(Character& character) {
  std::vector<double> mass(static_cast<std::size_t>(character.skeleton.num_joints()), 0.0);
  for (int v = 0; v < character.weights.outerSize(); ++v) {
    for (SparseWeights::InnerIterator it(character.weights, v); it; ++it) {
      mass[static_cast<std::size_t>(it.col())] += std::abs(it.value());
    }
  }
  // the removed joints carry no weight, so drop_leaves only re-indexes the kept columns
  return drop_leaves(character, [&](int j) { return mass[static_cast<std::size_t>(j)] == 0; });
}

SparseWeights onto_kept_joints(const SparseWeights& weights, const std::vector<int>& parents,
                               const std::vector<int>& kept) {
  const int n = static_cast<int>(parents.size());
  if (weights.cols() != n) {
    throw GeometryError("onto_kept_joints: the weights have " + std::to_string(weights.cols()) +
                        " joint columns, the skeleton " + std::to_string(n) + " joints");
  }
  std::vector<int> new_index(static_cast<std::size_t>(n), -1);
  for (std::size_t k = 0; k < kept.size(); ++k) new_index[static_cast<std::size_t>(kept[k])] = static_cast<int>(k);
  // each joint's column: its own if kept, else its nearest kept ancestor's
  std::vector<int> target(static_cast<std::size_t>(n), -1);
  for (int j = 0; j < n; ++j) {
    int a = j;
    while (a >= 0 && new_index[static_cast<std::size_t>(a)] < 0) a = parents[static_cast<std::size_t>(a)];
    if (a < 0) {
      throw GeometryError("onto_kept_joints: joint " + std::to_string(j) +
                          " has no kept ancestor (the root must be kept)");
    }
    target[static_cast<std::size_t>(j)] = new_index[static_cast<std::size_t>(a)];
  }
  std::vector<Eigen::Triplet<double>> triplets;
  for (int v = 0; v < weights.outerSize(); ++v) {
    for (SparseWeights::InnerIterator it(weights, v); it; ++it) {
      triplets.emplace_back(v, target[static_cast<std::size_t>(it.col())], it.value());
    }
  }
  SparseWeights out(weights.rows(), static_cast<Eigen::Index>(kept.size()));
  out.setFromTriplets(triplets.begin(), triplets.end());  // duplicates are summed
  return out;
}

}  // namespace skinlab::geometry

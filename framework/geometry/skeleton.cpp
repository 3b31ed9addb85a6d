#include "framework/geometry/skeleton.hpp"

#include <algorithm>
#include <deque>
#include <unordered_map>

namespace skinlab::geometry {

int Skeleton::find(const std::string& name) const {
  for (int j = 0; j < num_joints(); ++j) {
    if (names[j] == name) return j;
  }
  return -1;
}

int Skeleton::root() const {
  for (int j = 0; j < num_joints(); ++j) {
    if (parents[j] < 0) return j;
  }
  throw GeometryError("skeleton has no root joint");
}

std::vector<std::vector<int>> Skeleton::children() const {
  std::vector<std::vector<int>> out(names.size());
  for (int j = 0; j < num_joints(); ++j) {
    if (parents[j] >= 0) out[parents[j]].push_back(j);
  }
  return out;
}

std::vector<Bone> Skeleton::bones() const {
  const auto kids = children();
  std::vector<Bone> out;
  const int r = root();
  if (kids[r].empty()) return {Bone{r, r, true}};
  if (has_root_bone()) out.push_back(Bone{r, r, true});
  std::deque<int> level{r};
  while (!level.empty()) {
    const int p = level.front();
    level.pop_front();
    for (int c : kids[p]) {
      out.push_back(Bone{p, c, false});
      if (kids[c].empty()) out.push_back(Bone{c, c, true});
      level.push_back(c);
    }
  }
  return out;
}

bool Skeleton::has_root_bone() const {
  if (leaf_tips.rows() != num_joints() || num_joints() < 2) return false;
  const int r = root();
  const double diagonal =
      (positions.colwise().maxCoeff() - positions.colwise().minCoeff()).norm();
  return (leaf_tips.row(r) - positions.row(r)).norm() > 1e-5 * diagonal;
}

Eigen::Vector3d Skeleton::bone_end(const Bone& b) const {
  if (b.helper && leaf_tips.rows() > 0) return leaf_tips.row(b.start).transpose();
  return positions.row(b.end).transpose();
}

Eigen::MatrixXd Skeleton::bone_segments() const {
  const auto list = bones();
  Eigen::MatrixXd out(list.size(), 6);
  for (std::size_t b = 0; b < list.size(); ++b) {
    out.row(b) << positions.row(list[b].start), bone_end(list[b]).transpose();
  }
  return out;
}

void Skeleton::validate(const std::string& source) const {
  const std::string at = source + ": ";
  const int n = num_joints();
  if (n == 0) throw GeometryError(at + "skeleton has no joints");
  if (positions.rows() != n || positions.cols() != 3 || static_cast<int>(parents.size()) != n) {
    throw GeometryError(at + "skeleton has " + std::to_string(n) + " names, " +
                        std::to_string(positions.rows()) + "×" + std::to_string(positions.cols()) +
                        " positions and " + std::to_string(parents.size()) + " parents");
  }
  std::unordered_map<std::string, int> seen;
  for (int j = 0; j < n; ++j) {
    if (names[j].empty()) throw GeometryError(at + "joint " + std::to_string(j) + " has no name");
    if (auto [it, fresh] = seen.emplace(names[j], j); !fresh) {
      throw GeometryError(at + "duplicate joint name '" + names[j] + "' (joints " +
                          std::to_string(it->second) + " and " + std::to_string(j) + ")");
    }
    if (!positions.row(j).allFinite()) {
      throw GeometryError(at + "joint '" + names[j] + "' has a non-finite position");
    }
    if (parents[j] < -1 || parents[j] >= n || parents[j] == j) {
      throw GeometryError(at + "joint '" + names[j] + "' has an invalid parent index " +
                          std::to_string(parents[j]));
    }
  }
  if (leaf_tips.size() > 0 && (leaf_tips.rows() != n || leaf_tips.cols() != 3)) {
    throw GeometryError(at + "leaf tips are " + std::to_string(leaf_tips.rows()) + "×" +
                        std::to_string(leaf_tips.cols()) + " for " + std::to_string(n) +
                        " joints (expected " + std::to_string(n) + "×3)");
  }
  if (leaf_tips.size() > 0 && !leaf_tips.allFinite()) {
    for (int j = 0; j < n; ++j) {
      if (!leaf_tips.row(j).allFinite()) {
        throw GeometryError(at + "the leaf tip of joint '" + names[j] + "' is not finite");
      }
    }
  }
  std::vector<int> roots;
  for (int j = 0; j < n; ++j) {
    if (parents[j] < 0) roots.push_back(j);
  }
  if (roots.empty()) throw GeometryError(at + "skeleton has no root joint (every joint has a parent: a cycle)");
  if (roots.size() > 1) {
    throw GeometryError(at + "skeleton has " + std::to_string(roots.size()) + " roots: '" +
                        names[roots[0]] + "' and '" + names[roots[1]] + "'" +
                        (roots.size() > 2 ? " and others" : ""));
  }
  // Every joint must reach the root by following parents; a joint that does not is on a cycle.
  std::vector<int> state(n, 0);  // 0 unknown, 1 on current walk, 2 reaches the root
  state[roots[0]] = 2;
  for (int j = 0; j < n; ++j) {
    std::vector<int> walk;
    int k = j;
    while (state[k] == 0) {
      state[k] = 1;
      walk.push_back(k);
      k = parents[k];
    }
    if (state[k] == 1) {
      std::string cycle;
      for (auto it = std::find(walk.begin(), walk.end(), k); it != walk.end(); ++it) {
        cycle += "'" + names[*it] + "' -> ";
      }
      throw GeometryError(at + "skeleton hierarchy has a cycle: " + cycle + "'" + names[k] + "'");
    }
    for (int w : walk) state[w] = 2;
  }
}

Skeleton Skeleton::from_parent_names(std::vector<std::string> names, Eigen::MatrixXd positions,
                                     const std::vector<std::string>& parent_names,
                                     const std::string& source) {
  Skeleton s;
  s.names = std::move(names);
  s.positions = std::move(positions);
  if (parent_names.size() != s.names.size()) {
    throw GeometryError(source + ": " + std::to_string(s.names.size()) + " joints but " +
                        std::to_string(parent_names.size()) + " parent names");
  }
  std::unordered_map<std::string, int> index;
  for (int j = 0; j < s.num_joints(); ++j) index.emplace(s.names[j], j);
  s.parents.assign(s.names.size(), -1);
  for (int j = 0; j < s.num_joints(); ++j) {
    if (parent_names[j].empty()) continue;
    auto it = index.find(parent_names[j]);
    if (it == index.end()) {
      throw GeometryError(source + ": joint '" + s.names[j] + "' has unknown parent '" +
                          parent_names[j] + "'");
    }
    s.parents[j] = it->second;
  }
  s.validate(source);
  return s;
}

}  // namespace skinlab::geometry

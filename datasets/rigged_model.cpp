#include "datasets/rigged_model.hpp"

#include <cmath>

namespace skinlab::datasets {

using geometry::GeometryError;

Transforms compose_global(const Transforms& local, const std::vector<int>& parents,
                          const std::vector<std::string>& names, const std::string& source) {
  Transforms global(local.size());
  for (std::size_t j = 0; j < local.size(); ++j) {
    const int p = parents[j];
    if (p >= static_cast<int>(j)) {
      throw GeometryError(source + ": joint " + std::to_string(j) + " '" + names[j] +
                          "' has parent " + std::to_string(p) + ", which does not precede it");
    }
    global[j] = p < 0 ? local[j] : global[p] * local[j];
  }
  return global;
}

Eigen::Isometry3d to_isometry(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation,
                              const std::string& what, double tolerance) {
  if (!rotation.allFinite() || !translation.allFinite()) {
    throw GeometryError(what + ": non-finite transform");
  }
  const double error = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm();
  if (error > tolerance || rotation.determinant() < 0) {
    throw GeometryError(what + ": not a rotation (|RᵀR − I| = " + std::to_string(error) +
                        ", det = " + std::to_string(rotation.determinant()) +
                        "); scaled or mirrored joints are not supported");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation;
  T.translation() = translation;
  return T;
}

SourceRig to_source_rig(const RiggedModel& model) {
  const int n = static_cast<int>(model.joint_names.size());
  // Weight carried by each joint's subtree (parents precede children: one backward sweep).
  std::vector<double> subtree(n, 0.0);
  for (int v = 0; v < model.W.outerSize(); ++v) {
    for (geometry::SparseWeights::InnerIterator it(model.W, v); it; ++it) {
      subtree[it.col()] += it.value();
    }
  }
  for (int j = n - 1; j >= 0; --j) {
    if (model.parents[j] >= 0) subtree[model.parents[j]] += subtree[j];
  }
  // Keep a joint unless its root's subtree carries no weight.
  std::vector<int> root_of(n);
  for (int j = 0; j < n; ++j) root_of[j] = model.parents[j] < 0 ? j : root_of[model.parents[j]];
  // Joints under an unusable joint go too; they must not skin anything.
  std::vector<bool> dropped(n, false);
  for (int j = 0; j < n; ++j) {
    const bool unusable = !model.unusable.empty() && model.unusable[j];
    dropped[j] = unusable || (model.parents[j] >= 0 && dropped[model.parents[j]]);
    if (unusable && subtree[j] > 0) {
      throw GeometryError(model.name + ": joint " + std::to_string(j) + " '" +
                          model.joint_names[j] +
                          "' has a degenerate transform but its subtree carries weights");
    }
  }
  std::vector<int> kept, new_index(n, -1);
  std::string weighted_roots;
  int num_roots = 0;
  for (int j = 0; j < n; ++j) {
    if (subtree[root_of[j]] <= 0 || dropped[j]) continue;
    new_index[j] = static_cast<int>(kept.size());
    kept.push_back(j);
    if (model.parents[j] < 0) {
      ++num_roots;
      weighted_roots += (weighted_roots.empty() ? "'" : ", '") + model.joint_names[j] + "'";
    }
  }
  if (num_roots > 1) {
    throw GeometryError(model.name + ": " + std::to_string(num_roots) +
                        " root joints carry weights (" + weighted_roots +
                        "); a skeleton must be one tree");
  }

  SourceRig rig;
  rig.kept = kept;
  geometry::Character& c = rig.character;
  c.name = model.name;
  c.mesh.V = model.V;
  c.mesh.F = model.F;
  const int k = static_cast<int>(kept.size());
  c.skeleton.names.resize(k);
  c.skeleton.parents.resize(k);
  c.skeleton.positions.resize(k, 3);
  rig.bind.resize(k);
  for (int i = 0; i < k; ++i) {
    const int j = kept[i];
    c.skeleton.names[i] = model.joint_names[j];
    c.skeleton.parents[i] = model.parents[j] < 0 ? -1 : new_index[model.parents[j]];
    rig.bind[i] = model.bind[j];
    c.skeleton.positions.row(i) = model.bind[j].translation().transpose();
  }
  std::vector<Eigen::Triplet<double>> triplets;
  for (int v = 0; v < model.W.outerSize(); ++v) {
    for (geometry::SparseWeights::InnerIterator it(model.W, v); it; ++it) {
      triplets.emplace_back(v, new_index[it.col()], it.value());
    }
  }
  c.weights.resize(model.V.rows(), k);
  c.weights.setFromTriplets(triplets.begin(), triplets.end());
  c.validate();
  return rig;
}

Animation make_animation(const std::string& name, double fps,
                         const std::vector<Transforms>& global_frames, const SourceRig& rig) {
  Animation a;
  a.name = name;
  a.fps = fps;
  a.bind = rig.bind;
  a.frames.reserve(global_frames.size());
  for (const Transforms& frame : global_frames) {
    Transforms kept(rig.kept.size());
    for (std::size_t i = 0; i < rig.kept.size(); ++i) kept[i] = frame.at(rig.kept[i]);
    a.frames.push_back(std::move(kept));
  }
  return a;
}

}  // namespace skinlab::datasets

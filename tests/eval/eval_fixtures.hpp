#pragma once
// Shared by the metric tests: weight matrices from literals, metrics built through the registry,
// and small prepared characters (a hand-made two-joint arm and a random branching skeleton).

#include <torch/torch.h>

#include <random>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/eval/metric.hpp"

namespace skinlab::testing {

/// #rows×#cols float32 tensor from row literals.
inline torch::Tensor weights(const std::vector<std::vector<double>>& rows) {
  const auto n = static_cast<int64_t>(rows.size());
  const auto c = n ? static_cast<int64_t>(rows[0].size()) : 0;
  torch::Tensor t = torch::zeros({n, c}, torch::kFloat64);
  for (int64_t i = 0; i < n; ++i)
    for (int64_t j = 0; j < c; ++j) t[i][j] = rows[i][j];
  return t.to(torch::kFloat32);
}

inline std::shared_ptr<eval::Metric> make_metric(const std::string& yaml) {
  return metric_registry().create(config::Config::parse(yaml, "test.yaml").root());
}

/// Joints root (0,0,0) → child (0,1,0); bones 0: root→child, 1: the child's helper bone.
/// Vertices (0,0.5,0), (0,2,0), (1,1,0). No faces are needed by the metrics.
inline data::PreparedCharacter two_joint_arm(const std::string& name = "arm") {
  data::PreparedCharacter c;
  c.name = name;
  c.V = data::RowMatrixXd(3, 3);
  c.V << 0, 0.5, 0, 0, 2, 0, 1, 1, 0;
  c.joint_names = {"root", "child"};
  c.parents = {-1, 0};
  c.joints = data::RowMatrixXd(2, 3);
  c.joints << 0, 0, 0, 0, 1, 0;
  c.bones = data::RowMatrixXi(2, 2);
  c.bones << 0, 1, 1, 1;
  return c;
}

/// A random tree of `joints` joints (the parent of j drawn from 0..j−1, so branching joints
/// occur) with one bone per parent → child edge, then a helper bone per leaf (not the order of
/// Skeleton::bones(), which the metrics do not rely on), and `vertices` random vertices in
/// [−1, 1]³.
inline data::PreparedCharacter random_character(int joints, int vertices, unsigned seed,
                                                const std::string& name = "random") {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  data::PreparedCharacter c;
  c.name = name;
  c.V = data::RowMatrixXd(vertices, 3);
  for (int v = 0; v < vertices; ++v) c.V.row(v) << u(rng), u(rng), u(rng);
  std::vector<int> children(joints, 0);
  for (int j = 0; j < joints; ++j) {
    c.joint_names.push_back("j" + std::to_string(j));
    c.parents.push_back(j == 0 ? -1 : std::uniform_int_distribution<int>(0, j - 1)(rng));
    if (j > 0) ++children[c.parents[j]];
  }
  c.joints = data::RowMatrixXd(joints, 3);
  for (int j = 0; j < joints; ++j) c.joints.row(j) << u(rng), u(rng), u(rng);
  std::vector<std::pair<int, int>> bones;
  for (int j = 1; j < joints; ++j) bones.emplace_back(c.parents[j], j);
  for (int j = 0; j < joints; ++j)
    if (children[j] == 0) bones.emplace_back(j, j);
  c.bones = data::RowMatrixXi(static_cast<int>(bones.size()), 2);
  for (std::size_t b = 0; b < bones.size(); ++b)
    c.bones.row(static_cast<Eigen::Index>(b)) << bones[b].first, bones[b].second;
  return c;
}

/// #V×#B random row distributions with about `nonzeros` non-zero weights per row.
inline torch::Tensor random_weights(int64_t rows, int64_t bones, int nonzeros, uint64_t seed) {
  torch::manual_seed(seed);
  torch::Tensor w = torch::rand({rows, bones});
  const torch::Tensor keep = torch::rand({rows, bones}) < static_cast<double>(nonzeros) / bones;
  w = torch::where(keep, w, torch::zeros_like(w));
  w.select(1, 0).add_(1e-3);  // no empty row
  return w / w.sum(1, true);
}

}  // namespace skinlab::testing

// One character's evaluation by every registered metric, at the size of the dataset's larger
// characters (HeterSkinNet Sec. 4.1: 1K–5K vertices; 50 bones), default options: pruning at
// 0.25, and 10 poses for the deformation error.

#include <benchmark/benchmark.h>
#include <torch/torch.h>

#include <random>

#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/eval/metric.hpp"

namespace {

using namespace skinlab;

/// 40 joints: a chain of 30 and 10 side branches off every third chain joint, so 39 bones
/// between joints plus 11 helper bones at the leaves = 50 bones; random vertices in [−1, 1]³.
data::PreparedCharacter character(int vertices) {
  std::mt19937 rng(0);
  std::uniform_real_distribution<double> u(-1, 1);
  data::PreparedCharacter c;
  c.name = "bench";
  const int joints = 40;
  for (int j = 0; j < joints; ++j) {
    c.joint_names.push_back("j" + std::to_string(j));
    c.parents.push_back(j == 0 ? -1 : j < 30 ? j - 1 : (j - 30) * 3);
  }
  c.joints = data::RowMatrixXd(joints, 3);
  for (int j = 0; j < joints; ++j) c.joints.row(j) << u(rng), u(rng), u(rng);
  std::vector<int> children(joints, 0);
  for (int j = 1; j < joints; ++j) ++children[c.parents[j]];
  std::vector<std::pair<int, int>> bones;
  for (int j = 1; j < joints; ++j) bones.emplace_back(c.parents[j], j);
  for (int j = 0; j < joints; ++j)
    if (children[j] == 0) bones.emplace_back(j, j);
  c.bones = data::RowMatrixXi(static_cast<int>(bones.size()), 2);
  for (std::size_t b = 0; b < bones.size(); ++b)
    c.bones.row(static_cast<Eigen::Index>(b)) << bones[b].first, bones[b].second;
  c.V = data::RowMatrixXd(vertices, 3);
  for (int v = 0; v < vertices; ++v) c.V.row(v) << u(rng), u(rng), u(rng);
  return c;
}

/// #V×#B row distributions with about `nonzeros` weights per row (a K = 3 prediction scattered
/// to all bones has 3).
torch::Tensor random_weights(int64_t rows, int64_t bones, int nonzeros) {
  torch::Tensor w = torch::rand({rows, bones});
  w = torch::where(torch::rand({rows, bones}) < static_cast<double>(nonzeros) / bones, w,
                   torch::zeros_like(w));
  w.select(1, 0).add_(1e-3);
  return w / w.sum(1, true);
}

void BM_Metric(benchmark::State& state, const std::string& type) {
  torch::manual_seed(0);
  const auto c = character(static_cast<int>(state.range(0)));
  const auto metric =
      metric_registry().create(config::Config::parse("{type: " + type + "}").root());
  const torch::Tensor pred = random_weights(c.num_vertices(), c.num_bones(), 3);
  const torch::Tensor target = random_weights(c.num_vertices(), c.num_bones(), 2);
  state.counters["bones"] = c.num_bones();
  for (auto _ : state) {
    auto values = (*metric)({pred, target, &c});
    benchmark::DoNotOptimize(values);
  }
  state.SetItemsProcessed(state.iterations() * c.num_vertices());
}

BENCHMARK_CAPTURE(BM_Metric, precision_recall, std::string("precision_recall"))
    ->Arg(1000)
    ->Arg(5000)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Metric, avg_l1, std::string("avg_l1"))
    ->Arg(1000)
    ->Arg(5000)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Metric, deformation_error, std::string("deformation_error"))
    ->Arg(1000)
    ->Arg(5000)
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();

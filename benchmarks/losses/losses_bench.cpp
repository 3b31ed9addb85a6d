// Forward + backward of the HeterSkinNet losses at character sizes of the dataset
// (1K–8K vertices, K = 3 candidate bones) on a ring-like sparse Laplacian (7 entries per row,
// as a triangle mesh's one-ring).

#include <benchmark/benchmark.h>
#include <torch/torch.h>

#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/losses/loss.hpp"

namespace {

using namespace skinlab;

torch::Tensor ring_laplacian(int64_t n) {
  std::vector<int64_t> rows, cols;
  std::vector<float> values;
  for (int64_t i = 0; i < n; ++i) {
    for (int64_t d : {-3, -2, -1, 1, 2, 3}) {
      rows.push_back(i);
      cols.push_back((i + d + n) % n);
      values.push_back(-1.0f);
    }
    rows.push_back(i);
    cols.push_back(i);
    values.push_back(6.0f);
  }
  auto index = torch::stack({torch::tensor(rows), torch::tensor(cols)});
  return torch::sparse_coo_tensor(index, torch::tensor(values), {n, n}).coalesce();
}

void BM_Loss(benchmark::State& state, const std::string& type) {
  torch::manual_seed(0);
  const int64_t n = state.range(0), k = state.range(1);
  const auto loss = loss_registry().create(config::Config::parse("{type: " + type + "}").root());
  const torch::Tensor logits = torch::randn({n, k}).set_requires_grad(true);
  const torch::Tensor target = torch::softmax(torch::randn({n, k}), 1);
  const torch::Tensor lap = ring_laplacian(n);
  for (auto _ : state) {
    const torch::Tensor value = (*loss)({torch::softmax(logits, 1), target, lap});
    value.backward();
    benchmark::DoNotOptimize(logits.grad().data_ptr<float>());
  }
  state.SetItemsProcessed(state.iterations() * n);
}

BENCHMARK_CAPTURE(BM_Loss, kl, std::string("kl"))->ArgsProduct({{1000, 4000, 8000}, {3}});
BENCHMARK_CAPTURE(BM_Loss, laplacian_smoothing, std::string("laplacian_smoothing"))
    ->ArgsProduct({{1000, 4000, 8000}, {3, 16}});

}  // namespace

BENCHMARK_MAIN();

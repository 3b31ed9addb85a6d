// The mesh-sequence BiLSTM (experiments/bdlstm) at the paper's size (Sec. 4.1: mean_conv 9-9-9,
// latent 128, 3 × 128 LSTM): one training iteration (8 windows of 32 frames, both chains
// free-running, Eq. 3-5, backward, Adam step) and the generation of 15 frames from 3 initial
// frames (Table 1), on meshes of 354 vertices (the 0 A.D. wolf's count), 843 (the horse's) and
// 2,000. The mesh is a triangulated strip grid: only the vertex count and the one-ring's size
// matter to the cost.
#include <benchmark/benchmark.h>

#include "experiments/bdlstm/sequence_net.hpp"
#include "experiments/bdlstm/sequence_task.hpp"

namespace {

using namespace skinlab::bdlstm;

/// A 2-row-wide strip of triangles: vertex i joined to i+1 and i+2, both directions.
torch::Tensor strip_edges(std::int64_t n) {
  std::vector<std::int64_t> e;
  for (std::int64_t i = 0; i < n; ++i) {
    for (std::int64_t d : {1, 2}) {
      if (i + d < n) e.insert(e.end(), {i, i + d, i + d, i});
    }
  }
  return torch::tensor(e, torch::kInt64).view({-1, 2});
}

std::vector<torch::Tensor> frames(std::int64_t batch, std::int64_t n, int count) {
  std::vector<torch::Tensor> w;
  for (int t = 0; t < count; ++t) w.push_back(0.5 * torch::randn({batch, n, 9}));
  return w;
}

void BM_TrainingIteration(benchmark::State& state) {
  const std::int64_t n = state.range(0);
  torch::manual_seed(0);
  SequenceNetOptions o;
  o.scheme = state.range(1) ? "standard" : "shared";
  SequenceNet net(o, n, strip_edges(n));
  torch::optim::Adam adam(net.parameters(), torch::optim::AdamOptions(1e-3));
  const auto window = frames(8, n, 32);
  net.train();
  const auto iteration = [&] {
    adam.zero_grad();
    const Rollout r = net.rollout(window);
    sequence_loss(net, r, window, Objective{}).backward();
    adam.step();
  };
  iteration();  // warm-up: the allocator's first growth and libtorch's lazy set-up
  for (auto _ : state) iteration();
  state.counters["frames/s"] = benchmark::Counter(8.0 * 31 * 2, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Generate15From3(benchmark::State& state) {
  const std::int64_t n = state.range(0);
  torch::manual_seed(0);
  SequenceNet net(SequenceNetOptions{}, n, strip_edges(n));
  net.eval();
  torch::NoGradGuard no_grad;
  const auto initial = frames(1, n, 3);
  net.generate(initial, 15);  // warm-up
  for (auto _ : state) benchmark::DoNotOptimize(net.generate(initial, 15));
}

}  // namespace

BENCHMARK(BM_TrainingIteration)
    ->ArgsProduct({{354, 843, 2000}, {0, 1}})
    ->ArgNames({"vertices", "standard"})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3.0);
BENCHMARK(BM_Generate15From3)->Arg(354)->Arg(843)->Arg(2000)->ArgName("vertices")->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();

// Cost of resolving an experiment config (bases + overrides + validation through the
// registries), paid once per run and once per sweep point.

#include <benchmark/benchmark.h>

#include "framework/core/config.hpp"
#include "framework/train/run_options.hpp"

namespace {

using namespace skinlab;

const std::string kConfig = std::string(SKINLAB_SOURCE_DIR) + "/configs/ablations/no_smoothing.yaml";

void BM_LoadConfig(benchmark::State& state) {
  for (auto _ : state) {
    auto config = config::Config::load(kConfig, {"seed=3", "losses.0.weight=2"});
    benchmark::DoNotOptimize(config);
  }
}
BENCHMARK(BM_LoadConfig);

void BM_LoadAndValidate(benchmark::State& state) {
  for (auto _ : state) {
    auto options = train::RunOptions::from(config::Config::load(kConfig));
    benchmark::DoNotOptimize(options);
  }
}
BENCHMARK(BM_LoadAndValidate);

}  // namespace

BENCHMARK_MAIN();

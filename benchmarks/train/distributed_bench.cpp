// Data-parallel training (framework/train/distributed.hpp): the epoch time of HeterSkinNet at the
// paper's widths on the bundled 0 A.D. subset (9 training characters, euclidean inputs) in one
// process and in two processes over Gloo on this machine, each with the same effective batch
// of 2 characters per step. The time is the epochs' own (metrics.jsonl `seconds`: steps and
// validation), not process start-up or data loading; reported per epoch.
//
//   build/benchmarks/distributed_bench --benchmark_out_format=json
//       --benchmark_out=results/benchmarks/distributed_bench.json   (one command line)

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

/// The bundled subset with euclidean distances, prepared once per program run.
const fs::path& dataset() {
  static const fs::path file = [] {
    const fs::path dir = fs::temp_directory_path() / "skinlab-distributed-bench";
    fs::create_directories(dir);
    const fs::path out = dir / "bundled.h5";
    const std::string command = fmt::format(
        "cd '{}' && '{}' prepare configs/datasets/zeroad_bundled.yaml output={} "
        "\"distances=[{{type: euclidean}}]\" --threads 2 > /dev/null 2>&1",
        SKINLAB_SOURCE_DIR, SKINLAB_BINARY, out.string());
    if (std::system(command.c_str()) != 0) return fs::path();
    return out;
  }();
  return file;
}

/// Arguments: processes, threads per process, characters per process and step.
void BM_TrainEpoch(benchmark::State& state) {
  const int nproc = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const int batch = static_cast<int>(state.range(2));
  if (dataset().empty()) {
    state.SkipWithError("could not prepare the bundled dataset");
    return;
  }
  const fs::path results = dataset().parent_path() / "results";
  constexpr int kEpochs = 3;
  int run = 0;
  for (auto _ : state) {
    const std::string id = fmt::format("bench-{}x{}-{}", nproc, threads, run++);
    const std::string command = fmt::format(
        "cd '{}' && '{}' train configs/heterskinnet_bundled.yaml data.file={} "
        "data.distance=euclidean results_dir={} train.epochs={} train.batch={} --threads {} "
        "--run-id {}{} > /dev/null 2>&1",
        SKINLAB_SOURCE_DIR, SKINLAB_BINARY, dataset().string(), results.string(), kEpochs, batch,
        threads, id, nproc > 1 ? fmt::format(" --nproc {}", nproc) : "");
    if (std::system(command.c_str()) != 0) {
      state.SkipWithError(("command failed: " + command).c_str());
      return;
    }
    std::ifstream lines(results / "heterskinnet_bundled" / id / "metrics.jsonl");
    double seconds = 0;
    int epochs = 0;
    for (std::string line; std::getline(lines, line); ++epochs) {
      seconds += nlohmann::json::parse(line)["seconds"].get<double>();
    }
    state.SetIterationTime(seconds / std::max(epochs, 1));
  }
  fs::remove_all(results);
  state.counters["processes"] = nproc;
  state.counters["threads_per_process"] = threads;
  state.counters["characters_per_step"] = nproc * batch;
}

BENCHMARK(BM_TrainEpoch)
    ->ArgNames({"nproc", "threads", "batch"})
    ->Args({1, 1, 2})
    ->Args({1, 2, 2})
    ->Args({2, 1, 1})
    ->Iterations(2)
    ->UseManualTime()
    ->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();

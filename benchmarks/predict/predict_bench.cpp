// `skinlab predict` stage by stage (framework/predict/predictor.hpp), and beside it the
// Eigen-only `skinlab-predict` (infer/eigen_predictor.hpp, issue 24), with the bundled model
// (results/bundled/heterskinnet, the paper's widths; SKINLAB_PREDICT_MODEL overrides the
// directory) on synthetic characters of 1K, 3K and 5K vertices with 20 and 50 bones
// (benchmarks/synthetic_body.hpp), at 1 and 2 threads (libtorch intra-op threads and TBB).
//
// BM_Predict/size/bones/threads times one whole prediction from files: load (OBJ + rig text
// written once beforehand), normalise, distance, graph, network, map back, export (.glb);
// counters give each stage's mean seconds per prediction, `total_s` their sum, and `peak_rss_mb`
// the process's peak resident memory so far (getrusage; monotonic over the run, so read the
// first row of a size for that size alone). Model loading happens once, outside the timing.
//
// BM_PredictCli/size/bones/threads runs the `skinlab predict` program on the same files, one
// process per iteration: what a user waits for, with libtorch's start-up and the model's
// loading included; `peak_rss_mb` is the largest the program reported (`--timings` prints its
// VmHWM: getrusage's figure for children would count this process's pages the forked child
// held before exec). BM_CliStartup is `skinlab --help`
// (loading the shared libraries and their static initialisers, nothing of ours), and
// BM_LoadModel the bundled model's loading in process.
//
// The `Eigen` twins run `skinlab-predict`'s forward pass on the bundle's parameters.h5 in the
// same run: BM_EigenPredict in process, BM_EigenPredictCli the program (its --timings' model
// loading in `model_s`, as BM_PredictCli's), BM_EigenCliStartup `skinlab-predict --help` and
// BM_EigenLoadModel the loading of parameters.h5 and preparation.yaml in process.
//
// Like `skinlab` (framework/cli/main.cpp) the program keeps freed memory in the heap
// (keep_freed_memory), so the in-process figures are those of the program.
//
//   build/benchmarks/predict_bench --benchmark_out=predict.json --benchmark_out_format=json

#include <benchmark/benchmark.h>
#include <fmt/core.h>
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <torch/torch.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>

#include "benchmarks/synthetic_body.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/timing.hpp"
#include "framework/geometry/gltf_export.hpp"
#include "framework/geometry/load_character.hpp"
#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/rig_io.hpp"
#include "framework/infer/eigen_predictor.hpp"
#include "framework/predict/predictor.hpp"

namespace {

using namespace skinlab;
namespace fs = std::filesystem;

std::filesystem::path model_dir() {
  const char* env = std::getenv("SKINLAB_PREDICT_MODEL");
  return env != nullptr ? fs::path(env) : fs::path(SKINLAB_SOURCE_DIR) / "results" / "bundled" /
                                              "heterskinnet";
}

/// Sizes (index 0..2: ~1K, 3K, 5K vertices) for 20 bones (4 spine joints, 4 arms of 3 joints)
/// and 50 bones (8 spine joints, 6 arms of 6 joints).
bench::BodyShape shape(int size, int bones) {
  bench::BodyShape s;
  if (bones == 20) {
    const int sides[] = {14, 20, 25}, rings[] = {14, 30, 40};  // 5 tubes: 990, 3010, 5010
    s.sides = sides[size];
    s.rings = rings[size];
    s.arms = 4;
    s.spine_joints = 4;
    s.arm_at = {0.1, 0.25, 0.42};
  } else {
    const int sides[] = {12, 16, 20}, rings[] = {12, 27, 36};  // 7 tubes: 1022, 3038, 5054
    s.sides = sides[size];
    s.rings = rings[size];
    s.arms = 6;
    s.spine_joints = 8;
    s.arm_at = {0.08, 0.15, 0.22, 0.29, 0.36, 0.43};
  }
  return s;
}

const predict::Predictor* predictor() {
  static std::unique_ptr<predict::Predictor> p;
  if (!p && fs::exists(model_dir() / "config.yaml")) {
    p = std::make_unique<predict::Predictor>(predict::Predictor::load(model_dir()));
  }
  return p.get();
}

const infer::EigenPredictor* eigen_predictor() {
  static std::unique_ptr<infer::EigenPredictor> p;
  if (!p && fs::exists(model_dir() / "parameters.h5")) {
    p = std::make_unique<infer::EigenPredictor>(infer::EigenPredictor::load(model_dir()));
  }
  return p.get();
}

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

/// The synthetic character of `size` and `bones` as OBJ + rig text in a scratch directory.
struct BodyFiles {
  fs::path dir, obj, rig, out;
  int vertices = 0, bones = 0;
  BodyFiles(int size, int bone_count) {
    const geometry::Character body = bench::make_body(shape(size, bone_count));
    dir = fs::temp_directory_path() / "skinlab-predict-bench";
    fs::create_directories(dir);
    obj = dir / "body.obj";
    rig = dir / "body_rig.txt";
    out = dir / "body.glb";
    geometry::write_obj(obj, body.mesh);
    geometry::write_rig(rig, body.skeleton, {});
    vertices = body.mesh.num_vertices();
    bones = static_cast<int>(body.skeleton.bones().size());
  }
  ~BodyFiles() { fs::remove_all(dir); }
  BodyFiles(const BodyFiles&) = delete;
  BodyFiles& operator=(const BodyFiles&) = delete;
};

/// Runs a shell command, failing the benchmark if it does not exit with 0.
bool run(benchmark::State& state, const std::string& command) {
  if (std::system(command.c_str()) != 0) {
    state.SkipWithError(("command failed: " + command).c_str());
    return false;
  }
  return true;
}

/// One whole prediction in process with `p` (libtorch's or the Eigen one).
void predict_in_process(benchmark::State& state, const infer::PredictEngine* p) {
  const int size = static_cast<int>(state.range(0));
  const int bones = static_cast<int>(state.range(1));
  const int threads = static_cast<int>(state.range(2));
  if (p == nullptr) {
    state.SkipWithError(("no model in " + model_dir().string() +
                         " (skinlab bundle, or set SKINLAB_PREDICT_MODEL)").c_str());
    return;
  }
  const BodyFiles files(size, bones);
  const fs::path &obj = files.obj, &rig = files.rig, &out = files.out;
  torch::set_num_threads(threads);
  tbb::global_control tbb_threads(tbb::global_control::max_allowed_parallelism, threads);

  predict::StageTimes sum;
  int prepared_vertices = 0;
  for (auto _ : state) {
    predict::StageTimes t;
    auto start = std::chrono::steady_clock::now();
    const geometry::Character input = geometry::load_character(obj, rig);
    t.load = seconds_since(start);
    const predict::Prediction prediction = p->predict(input, {}, &t);
    start = std::chrono::steady_clock::now();
    geometry::Character result = input;
    result.weights = prediction.joint_weights;
    geometry::write_gltf(out, result);
    t.export_ = seconds_since(start);
    prepared_vertices = prediction.prepared.num_vertices();
    sum.load += t.load;
    sum.normalise += t.normalise;
    sum.distance += t.distance;
    sum.graph += t.graph;
    sum.network += t.network;
    sum.map_back += t.map_back;
    sum.export_ += t.export_;
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["vertices"] = files.vertices;
  state.counters["prepared_vertices"] = prepared_vertices;
  state.counters["bones"] = files.bones;
  state.counters["threads"] = threads;
  state.counters["load_s"] = sum.load / n;
  state.counters["normalise_s"] = sum.normalise / n;
  state.counters["distance_s"] = sum.distance / n;
  state.counters["graph_s"] = sum.graph / n;
  state.counters["network_s"] = sum.network / n;
  state.counters["map_back_s"] = sum.map_back / n;
  state.counters["export_s"] = sum.export_ / n;
  state.counters["total_s"] = sum.total() / n;
  state.counters["peak_rss_mb"] = peak_rss_mb();
}

void BM_Predict(benchmark::State& state) { predict_in_process(state, predictor()); }
void BM_EigenPredict(benchmark::State& state) { predict_in_process(state, eigen_predictor()); }

/// The number after the last `key` ("peak memory ", "model loading ") in what `--timings`
/// printed into `log`, or -1.
double reported(const fs::path& log, const std::string& key) {
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.rfind(key);
  return at == std::string::npos ? -1.0 : std::stod(text.substr(at + key.size()));
}

/// One process per iteration: `skinlab predict` or (`eigen`) `skinlab-predict`.
void predict_program(benchmark::State& state, bool eigen) {
  const int size = static_cast<int>(state.range(0));
  const int bones = static_cast<int>(state.range(1));
  const int threads = static_cast<int>(state.range(2));
  const BodyFiles files(size, bones);
  const fs::path log = files.dir / "predict.log";
  const std::string command =
      fmt::format("'{}' --threads {} --log-level warn {}'{}' --rig '{}' --model '{}' "
                  "--out '{}' --timings > '{}'",
                  eigen ? SKINLAB_PREDICT_BINARY : SKINLAB_BINARY, threads,
                  eigen ? "" : "predict ", files.obj.string(), files.rig.string(),
                  model_dir().string(), files.out.string(), log.string());
  double peak = 0, model = 0;
  for (auto _ : state) {
    if (!run(state, command)) return;
    peak = std::max(peak, reported(log, "peak memory "));
    model += reported(log, "model loading ");
  }
  state.counters["vertices"] = files.vertices;
  state.counters["bones"] = files.bones;
  state.counters["threads"] = threads;
  state.counters["peak_rss_mb"] = peak;
  state.counters["model_s"] = model / static_cast<double>(state.iterations());
}

void BM_PredictCli(benchmark::State& state) { predict_program(state, false); }
void BM_EigenPredictCli(benchmark::State& state) { predict_program(state, true); }

void startup(benchmark::State& state, const char* binary) {
  const std::string command = fmt::format("'{}' --help > /dev/null", binary);
  for (auto _ : state) {
    if (!run(state, command)) return;
  }
}

void BM_CliStartup(benchmark::State& state) { startup(state, SKINLAB_BINARY); }
void BM_EigenCliStartup(benchmark::State& state) { startup(state, SKINLAB_PREDICT_BINARY); }

void BM_LoadModel(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(predict::Predictor::load(model_dir()));
  }
}

void BM_EigenLoadModel(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(infer::EigenPredictor::load(model_dir()));
  }
}

BENCHMARK(BM_Predict)
    ->ArgsProduct({{0, 1, 2}, {20, 50}, {1, 2}})
    ->ArgNames({"size", "bones", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_EigenPredict)
    ->ArgsProduct({{0, 1, 2}, {20, 50}, {1, 2}})
    ->ArgNames({"size", "bones", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_PredictCli)
    ->ArgsProduct({{0, 1, 2}, {20, 50}, {1, 2}})
    ->ArgNames({"size", "bones", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_EigenPredictCli)
    ->ArgsProduct({{0, 1, 2}, {20, 50}, {1, 2}})
    ->ArgNames({"size", "bones", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_CliStartup)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EigenCliStartup)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LoadModel)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EigenLoadModel)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  keep_freed_memory();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

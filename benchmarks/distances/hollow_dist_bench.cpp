// HollowDist (HeterSkinNet Sec. 3.1, Algorithm 1, Eq. 1) at the paper's grid size, 88³, on
// synthetic characters of the dataset's sizes (1K–5K vertices, chain skeletons of 20–100 bones):
// a noised closed tube wound as a helix (whose bounding box is nearly a cube, the worst case for
// the stored slab of the grid) plus a detached sphere on its axis that only restarts reach.
//
// Stages timed separately: voxelisation (once per character), the searches of all bones
// (Algorithm 1 lines 2–25, TBB over bones), Eq. 1 for every vertex and bone; then the whole
// `compute`. Threads (1, 2) are a benchmark argument (tbb::global_control). Memory: the peak
// resident set (VmHWM, reset through /proc/self/clear_refs before each benchmark) and the bytes
// of the buffers the computation holds.
//
//   build/benchmarks/hollow_dist_bench --benchmark_out=hollow.json --benchmark_out_format=json

#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <fstream>
#include <random>
#include <string>

#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/distances/euclidean.hpp"
#include "framework/distances/hollow_dist.hpp"

namespace {

using namespace skinlab;
using geometry::Mesh;
using geometry::Skeleton;

struct Character {
  Mesh mesh;
  Skeleton skeleton;
};

struct Size {
  int rings, sides, sphere_u, sphere_v, joints;
};
// About 1K, 3K and 5K vertices with 20, 60 and 100 bones (joints − 1 bones + 1 leaf helper).
constexpr Size kSizes[] = {{36, 25, 12, 8, 20}, {100, 28, 16, 12, 60}, {160, 30, 20, 10, 100}};

constexpr double kHelixRadius = 0.4, kHeight = 1.0, kTurns = 2.5, kTube = 0.08;

Eigen::Vector3d helix(double t) {
  const double a = 2 * M_PI * kTurns * t;
  return {kHelixRadius * std::cos(a), kHelixRadius * std::sin(a), kHeight * (t - 0.5)};
}

Character make_character(const Size& size) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> noise(-0.05, 0.05);
  std::vector<Eigen::Vector3d> V;
  std::vector<Eigen::Vector3i> F;
  // Tube: rings along the helix, capped at both ends.
  for (int i = 0; i < size.rings; ++i) {
    const double t = static_cast<double>(i) / (size.rings - 1);
    const double a = 2 * M_PI * kTurns * t;
    const Eigen::Vector3d tangent = (helix(t + 1e-4) - helix(t - 1e-4)).normalized();
    const Eigen::Vector3d normal(-std::cos(a), -std::sin(a), 0);  // towards the axis, ⟂ tangent
    const Eigen::Vector3d binormal = tangent.cross(normal);
    for (int j = 0; j < size.sides; ++j) {
      const double b = 2 * M_PI * j / size.sides;
      const double r = kTube * (1 + noise(rng));
      V.push_back(helix(t) + r * (std::cos(b) * normal + std::sin(b) * binormal));
    }
  }
  for (int i = 0; i + 1 < size.rings; ++i) {
    for (int j = 0; j < size.sides; ++j) {
      const int a = i * size.sides + j, b = i * size.sides + (j + 1) % size.sides;
      F.emplace_back(a, b, b + size.sides);
      F.emplace_back(a, b + size.sides, a + size.sides);
    }
  }
  for (int end = 0; end < 2; ++end) {
    const int centre = static_cast<int>(V.size());
    V.push_back(helix(end));
    const int ring = end * (size.rings - 1) * size.sides;
    for (int j = 0; j < size.sides; ++j) {
      F.emplace_back(centre, ring + j, ring + (j + 1) % size.sides);
    }
  }
  // Detached sphere on the helix axis.
  const int base = static_cast<int>(V.size());
  const double R = 0.15;
  V.emplace_back(0, 0, R);
  for (int j = 1; j < size.sphere_v; ++j) {
    for (int i = 0; i < size.sphere_u; ++i) {
      const double u = 2 * M_PI * i / size.sphere_u, v = M_PI * j / size.sphere_v;
      V.push_back(
          R * Eigen::Vector3d(std::sin(v) * std::cos(u), std::sin(v) * std::sin(u), std::cos(v)));
    }
  }
  const int south = static_cast<int>(V.size());
  V.emplace_back(0, 0, -R);
  auto ring = [&](int j, int i) { return base + 1 + (j - 1) * size.sphere_u + i % size.sphere_u; };
  for (int i = 0; i < size.sphere_u; ++i) {
    F.emplace_back(base, ring(1, i), ring(1, i + 1));
    F.emplace_back(south, ring(size.sphere_v - 1, i + 1), ring(size.sphere_v - 1, i));
    for (int j = 1; j + 1 < size.sphere_v; ++j) {
      F.emplace_back(ring(j, i), ring(j + 1, i), ring(j + 1, i + 1));
      F.emplace_back(ring(j, i), ring(j + 1, i + 1), ring(j, i + 1));
    }
  }
  Character c;
  c.mesh.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (std::size_t v = 0; v < V.size(); ++v) c.mesh.V.row(v) = V[v];
  c.mesh.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t f = 0; f < F.size(); ++f) c.mesh.F.row(f) = F[f];
  c.mesh.validate("benchmark character");
  // Chain skeleton along the tube's centre line.
  std::vector<std::string> names, parents;
  Eigen::MatrixXd joints(size.joints, 3);
  for (int j = 0; j < size.joints; ++j) {
    joints.row(j) = helix(0.03 + 0.94 * j / (size.joints - 1));
    names.push_back("j" + std::to_string(j));
    parents.push_back(j == 0 ? "" : names[j - 1]);
  }
  c.skeleton = Skeleton::from_parent_names(names, joints, parents, "benchmark skeleton");
  return c;
}

const Character& character(int index) {
  static const Character characters[] = {make_character(kSizes[0]), make_character(kSizes[1]),
                                         make_character(kSizes[2])};
  return characters[index];
}

// ---- memory ------------------------------------------------------------------------------------

double status_mb(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1)) / 1024.0;
  }
  return -1;
}

/// Resets VmHWM to the current resident set (Linux ≥ 4.0), so each benchmark reports its own peak.
double reset_peak() {
  std::ofstream("/proc/self/clear_refs") << "5";
  return status_mb("VmRSS");
}

void report(benchmark::State& state, const Character& c, double baseline_mb) {
  state.counters["vertices"] = c.mesh.num_vertices();
  state.counters["bones"] = static_cast<double>(c.skeleton.bones().size());
  state.counters["peak_MB"] = status_mb("VmHWM");
  state.counters["peak_over_start_MB"] = status_mb("VmHWM") - baseline_mb;
}

const distances::HollowDist& hollow_dist() {
  static const distances::HollowDist hd(distances::HollowDist::Options{88, 2});
  return hd;
}

// ---- stages ------------------------------------------------------------------------------------

void BM_Voxelize(benchmark::State& state) {
  const Character& c = character(static_cast<int>(state.range(0)));
  const double baseline = reset_peak();
  for (auto _ : state) {
    const auto voxels = hollow_dist().voxelize(c.mesh, c.skeleton);
    benchmark::DoNotOptimize(voxels.num_mesh_cells());
  }
  const auto voxels = hollow_dist().voxelize(c.mesh, c.skeleton);
  const auto& d = voxels.grid().dims();
  state.counters["cells"] = static_cast<double>(d[0]) * d[1] * d[2];
  state.counters["mesh_cells"] = voxels.num_mesh_cells();
  state.counters["grid_MB"] = voxels.bytes() / 1048576.0;
  report(state, c, baseline);
}

void BM_SearchAllBones(benchmark::State& state) {
  const Character& c = character(static_cast<int>(state.range(0)));
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(1));
  const auto voxels = hollow_dist().voxelize(c.mesh, c.skeleton);
  const Eigen::MatrixXd segments = c.skeleton.bone_segments();
  const int B = static_cast<int>(segments.rows());
  const double baseline = reset_peak();
  std::size_t buffer_bytes = 0;
  for (auto _ : state) {
    tbb::enumerable_thread_specific<distances::HollowBfs> workers(
        [&] { return distances::HollowBfs(voxels); });
    tbb::parallel_for(tbb::blocked_range<int>(0, B), [&](const tbb::blocked_range<int>& r) {
      auto& bfs = workers.local();
      for (int b = r.begin(); b < r.end(); ++b) {
        bfs.run(segments.row(b).head<3>(), segments.row(b).tail<3>());
      }
    });
    buffer_bytes = 0;
    int restarts = 0;
    for (const auto& w : workers) buffer_bytes += w.bytes(), restarts += w.restarts();
    benchmark::DoNotOptimize(restarts);
  }
  state.counters["search_buffers_MB"] = buffer_bytes / 1048576.0;
  report(state, c, baseline);
}

// Eq. 1 alone: each bone's search runs untimed before its vertex distances are timed.
void BM_VertexDistances(benchmark::State& state) {
  const Character& c = character(static_cast<int>(state.range(0)));
  const auto voxels = hollow_dist().voxelize(c.mesh, c.skeleton);
  const Eigen::MatrixXd segments = c.skeleton.bone_segments();
  distances::HollowBfs bfs(voxels);
  Eigen::VectorXd column(c.mesh.num_vertices());
  const double baseline = reset_peak();
  int restarts = 0;
  for (auto _ : state) {
    double seconds = 0;
    restarts = 0;
    for (Eigen::Index b = 0; b < segments.rows(); ++b) {
      bfs.run(segments.row(b).head<3>(), segments.row(b).tail<3>());
      restarts += bfs.restarts();
      const auto start = std::chrono::steady_clock::now();
      bfs.vertex_distances(c.mesh, segments.row(b).head<3>(), segments.row(b).tail<3>(), column,
                           "bone");
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      benchmark::DoNotOptimize(column.data());
    }
    state.SetIterationTime(seconds);
  }
  state.counters["restarts_per_bone"] = static_cast<double>(restarts) / segments.rows();
  report(state, c, baseline);
}

void BM_HollowDistTotal(benchmark::State& state) {
  const Character& c = character(static_cast<int>(state.range(0)));
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(1));
  const double baseline = reset_peak();
  for (auto _ : state) {
    const Eigen::MatrixXd D = hollow_dist().compute(c.mesh, c.skeleton);
    benchmark::DoNotOptimize(D.data());
  }
  report(state, c, baseline);
}

void BM_Euclidean(benchmark::State& state) {
  const Character& c = character(static_cast<int>(state.range(0)));
  const auto euclidean =
      distance_registry().create(config::Config::parse("{type: euclidean}").root());
  const double baseline = reset_peak();
  for (auto _ : state) {
    const Eigen::MatrixXd D = euclidean->compute(c.mesh, c.skeleton);
    benchmark::DoNotOptimize(D.data());
  }
  report(state, c, baseline);
}

// range(0): character 0/1/2 = ~1K/20, ~3K/60, ~5K/100; range(1): threads.
BENCHMARK(BM_Voxelize)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SearchAllBones)
    ->ArgsProduct({{0, 1, 2}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_VertexDistances)->DenseRange(0, 2)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_HollowDistTotal)
    ->ArgsProduct({{0, 1, 2}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Euclidean)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::AddCustomContext("hollow_dist_grid", "88^3 cube, margin 2 cells");
  benchmark::AddCustomContext(
      "characters", "helix tube + detached sphere: ~1K/20, ~3K/60, ~5K/100 (vertices/bones)");
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

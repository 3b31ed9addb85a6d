// volumetric_geodesic on synthetic closed limbs: a tube whose centre line waves in a plane (so
// parts of it occlude others), capped at both ends, of about 1K, 3K and 5K vertices, with a
// chain skeleton of 20 or 60 bones along the centre line (plus the leaf's helper bone).
// Arguments: vertices, bones, TBB threads, samples_per_bone (the default 10, and 2 and 5 on the
// largest case to show what the samples cost). Counters: seconds per stage (AABB tree and surface
// graph, visibility, Dijkstra) per call, and the process's peak resident memory (VmHWM, reset
// before each benchmark through /proc/self/clear_refs) in MB.

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/distances/volumetric_geodesic.hpp"

namespace {

using namespace skinlab;

constexpr int kAround = 32;  // vertices per ring
constexpr double kPi = 3.14159265358979323846;

/// Centre line of a 1.8 m limb that waves ±0.15 m in x twice over its height.
Eigen::Vector3d centre(double s) {
  return {0.15 * std::sin(4 * kPi * s), 0.0, 1.8 * s};
}

geometry::Mesh wavy_tube(int target_vertices) {
  const int rings = std::max(2, (target_vertices - 2) / kAround);
  const double radius = 0.08;
  geometry::Mesh mesh;
  mesh.V.resize(rings * kAround + 2, 3);
  for (int r = 0; r < rings; ++r) {
    const double s = static_cast<double>(r) / (rings - 1);
    const Eigen::Vector3d c = centre(s);
    const Eigen::Vector3d tangent = (centre(s + 1e-6) - centre(s - 1e-6)).normalized();
    const Eigen::Vector3d y(0, 1, 0);
    const Eigen::Vector3d normal = y.cross(tangent).normalized();
    for (int a = 0; a < kAround; ++a) {
      const double t = 2 * kPi * a / kAround;
      mesh.V.row(r * kAround + a) = (c + radius * (std::cos(t) * normal + std::sin(t) * y)).transpose();
    }
  }
  const int bottom = rings * kAround, top = bottom + 1;
  mesh.V.row(bottom) = centre(0).transpose();
  mesh.V.row(top) = centre(1).transpose();
  std::vector<Eigen::Vector3i> faces;
  for (int r = 0; r + 1 < rings; ++r) {
    for (int a = 0; a < kAround; ++a) {
      const int i = r * kAround + a, j = r * kAround + (a + 1) % kAround;
      faces.emplace_back(i, j, j + kAround);
      faces.emplace_back(i, j + kAround, i + kAround);
    }
  }
  for (int a = 0; a < kAround; ++a) {
    faces.emplace_back(bottom, (a + 1) % kAround, a);
    faces.emplace_back(top, (rings - 1) * kAround + a, (rings - 1) * kAround + (a + 1) % kAround);
  }
  mesh.F.resize(faces.size(), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) mesh.F.row(f) = faces[f].transpose();
  return mesh;
}

geometry::Skeleton chain_skeleton(int bones) {
  std::vector<std::string> names, parents;
  Eigen::MatrixXd positions(bones + 1, 3);
  for (int j = 0; j <= bones; ++j) {
    names.push_back("j" + std::to_string(j));
    parents.push_back(j == 0 ? "" : names[j - 1]);
    positions.row(j) = centre(0.02 + 0.96 * j / bones).transpose();
  }
  return geometry::Skeleton::from_parent_names(names, positions, parents, "bench chain");
}

double peak_memory_mb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  }
  return 0;
}

void BM_VolumetricGeodesic(benchmark::State& state) {
  const geometry::Mesh mesh = wavy_tube(static_cast<int>(state.range(0)));
  const geometry::Skeleton skeleton = chain_skeleton(static_cast<int>(state.range(1)));
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(state.range(2)));
  const distances::VolumetricGeodesic distance(
      distances::VolumetricGeodesic::Options::from(config::Config::parse(
          "{samples_per_bone: " + std::to_string(state.range(3)) + "}").root()));
  std::ofstream("/proc/self/clear_refs") << "5";  // peak RSS := current RSS
  distances::VolumetricGeodesicTimings sum, t;
  for (auto _ : state) {
    const Eigen::MatrixXd D = distance.compute(mesh, skeleton, &t);
    benchmark::DoNotOptimize(D.data());
    sum.aabb += t.aabb;
    sum.visibility += t.visibility;
    sum.dijkstra += t.dijkstra;
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["V"] = mesh.num_vertices();
  state.counters["B"] = static_cast<double>(skeleton.bones().size());
  state.counters["aabb_s"] = sum.aabb / n;
  state.counters["visibility_s"] = sum.visibility / n;
  state.counters["dijkstra_s"] = sum.dijkstra / n;
  state.counters["peak_MB"] = peak_memory_mb();
}

BENCHMARK(BM_VolumetricGeodesic)
    ->ArgNames({"vertices", "bones", "threads", "samples"})
    ->ArgsProduct({{1000, 3000, 5000}, {20, 60}, {1, 2}, {10}})
    ->Args({5000, 60, 1, 2})
    ->Args({5000, 60, 1, 5})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();

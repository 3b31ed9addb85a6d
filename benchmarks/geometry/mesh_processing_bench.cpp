// Mesh pre-processing and neighbourhoods (HeterSkinNet Sec. 4.1, 3.3, 3.4) at the dataset's
// vertex range after subdivision, 1K–5K: synthetic grid tori of n×n vertices, n = 32, 55, 71
// (1024, 3025, 5041 vertices; major radius 0.3 m, minor 0.1 m, so the 6 cm geodesic ball holds
// tens of vertices as on a 1 m character). Geodesic neighbours run with 1 and 2 TBB threads.
// Allocating and freeing the same few hundred KB in a tight loop can make glibc trim and re-fault
// the heap on every iteration, which shows as a jump at one size (system time, not the
// algorithm); MALLOC_TRIM_THRESHOLD_=67108864 MALLOC_MMAP_THRESHOLD_=67108864 removes it.

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>

#include "framework/geometry/acap.hpp"
#include "framework/geometry/geodesic_neighbours.hpp"
#include "framework/geometry/laplacian.hpp"
#include "framework/geometry/merge_vertices.hpp"
#include "framework/geometry/one_ring.hpp"
#include "framework/geometry/subdivide.hpp"

namespace {

using namespace skinlab::geometry;

Mesh torus(int n, int m) {
  constexpr double kMajor = 0.3, kMinor = 0.1, kTwoPi = 6.283185307179586;
  Mesh mesh;
  mesh.V.resize(n * m, 3);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      const double u = kTwoPi * i / n, v = kTwoPi * j / m;
      mesh.V.row(i * m + j) << (kMajor + kMinor * std::cos(v)) * std::cos(u),
          (kMajor + kMinor * std::cos(v)) * std::sin(u), kMinor * std::sin(v);
    }
  }
  mesh.F.resize(2 * n * m, 3);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      const int a = i * m + j, b = ((i + 1) % n) * m + j, c = i * m + (j + 1) % m,
                d = ((i + 1) % n) * m + (j + 1) % m;
      mesh.F.row(2 * (i * m + j)) << a, b, d;
      mesh.F.row(2 * (i * m + j) + 1) << a, d, c;
    }
  }
  return mesh;
}

// Every triangle with its own three vertices, as exporters write hard-edged meshes.
Mesh triangle_soup(const Mesh& mesh) {
  Mesh soup;
  soup.V.resize(3 * mesh.num_faces(), 3);
  soup.F.resize(mesh.num_faces(), 3);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      soup.V.row(3 * f + k) = mesh.V.row(mesh.F(f, k));
      soup.F(f, k) = 3 * f + k;
    }
  }
  return soup;
}

void set_counters(benchmark::State& state, int vertices) {
  state.counters["vertices"] = vertices;
  state.SetItemsProcessed(state.iterations() * vertices);
}

void BM_MergeVertices(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const Mesh soup = triangle_soup(torus(n, n));
  for (auto _ : state) benchmark::DoNotOptimize(merge_vertices(soup).mesh.V.data());
  set_counters(state, soup.num_vertices());
}

// One 1-to-4 step from a quarter of the size to about the size.
void BM_Subdivide(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0)) / 2;
  const Mesh coarse = torus(n, n);
  int result = 0;
  for (auto _ : state) {
    const SubdividedMesh s = subdivide(coarse, {coarse.num_vertices() + 1, 1 << 30});
    result = s.mesh.num_vertices();
    benchmark::DoNotOptimize(s.S.valuePtr());
  }
  set_counters(state, result);
}

void BM_OneRing(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const Mesh mesh = torus(n, n);
  for (auto _ : state) benchmark::DoNotOptimize(one_ring(mesh).edges.data());
  set_counters(state, mesh.num_vertices());
}

void BM_GeodesicNeighbours(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const Mesh mesh = torus(n, n);
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              static_cast<size_t>(state.range(1)));
  double ball = 0;
  for (auto _ : state) {
    const GeodesicNeighbours g = geodesic_neighbours(mesh);
    ball = g.ball_size.cast<double>().mean();
    benchmark::DoNotOptimize(g.edges.data());
  }
  set_counters(state, mesh.num_vertices());
  state.counters["threads"] = static_cast<double>(state.range(1));
  state.counters["mean_ball"] = ball;
}

void BM_Laplacian(benchmark::State& state, LaplacianKind kind) {
  const int n = static_cast<int>(state.range(0));
  const Mesh mesh = torus(n, n);
  for (auto _ : state) benchmark::DoNotOptimize(laplacian(mesh, {kind}).valuePtr());
  set_counters(state, mesh.num_vertices());
}

/// ACAP features (mesh-sequence BiLSTM Sec. 3.1): the encoder's set-up (weights, Gram matrices,
/// the Poisson factorisation), encoding one frame (a twist of the torus) and decoding it.
Mesh twisted(const Mesh& m) {
  Mesh out = m;
  for (int i = 0; i < m.num_vertices(); ++i) {
    const double a = 2.0 * m.V(i, 0);
    const double y = m.V(i, 1), z = m.V(i, 2);
    out.V(i, 1) = std::cos(a) * y - std::sin(a) * z;
    out.V(i, 2) = std::sin(a) * y + std::cos(a) * z;
  }
  return out;
}
void BM_AcapSetUp(benchmark::State& state) {
  const Mesh mesh = torus(static_cast<int>(state.range(0)), static_cast<int>(state.range(0)));
  for (auto _ : state) {
    const AcapEncoder acap(mesh, "torus");
    benchmark::DoNotOptimize(acap.num_parts());
  }
  set_counters(state, mesh.num_vertices());
}
void BM_AcapEncode(benchmark::State& state) {
  const Mesh mesh = torus(static_cast<int>(state.range(0)), static_cast<int>(state.range(0)));
  const AcapEncoder acap(mesh, "torus");
  const Eigen::MatrixXd frame = twisted(mesh).V;
  for (auto _ : state) benchmark::DoNotOptimize(acap.encode_sequence({frame}).front().data());
  set_counters(state, mesh.num_vertices());
}
void BM_AcapDecode(benchmark::State& state) {
  const Mesh mesh = torus(static_cast<int>(state.range(0)), static_cast<int>(state.range(0)));
  const AcapEncoder acap(mesh, "torus");
  const Eigen::MatrixXd features = acap.encode(twisted(mesh).V);
  for (auto _ : state) benchmark::DoNotOptimize(acap.decode(features).data());
  set_counters(state, mesh.num_vertices());
}

BENCHMARK(BM_AcapSetUp)->Arg(32)->Arg(55)->Arg(71)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AcapEncode)->Arg(32)->Arg(55)->Arg(71)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AcapDecode)->Arg(32)->Arg(55)->Arg(71)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MergeVertices)->Arg(32)->Arg(55)->Arg(71)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Subdivide)->Arg(32)->Arg(55)->Arg(71)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_OneRing)->Arg(32)->Arg(55)->Arg(71)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_GeodesicNeighbours)
    ->ArgsProduct({{32, 55, 71}, {1, 2}})
    ->ArgNames({"n", "threads"})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Laplacian, uniform, LaplacianKind::kUniform)
    ->Arg(32)->Arg(55)->Arg(71)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Laplacian, cotangent, LaplacianKind::kCotangent)
    ->Arg(32)->Arg(55)->Arg(71)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();

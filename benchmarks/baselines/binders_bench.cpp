// Bind time of the non-learned binders (baselines/geo_voxel, baselines/bone_heat) with their
// default options on synthetic characters of the dataset's sizes (1K, 3K, 5K vertices) with 33
// bones: a closed vertical body tube and six closed horizontal arm tubes radiating from it
// (intersecting the body, as game meshes' separate parts do), a 2-bone spine and a 4-bone chain
// per arm (plus leaf helper bones). Threads (1, 2) are a benchmark argument
// (tbb::global_control); the machine has 2 cores.
//
// BM_Dataset/<binder> binds every character of a prepared dataset file (SKINLAB_BINDERS_DATASET;
// skipped when unset) or only the test characters of split SKINLAB_BINDERS_SPLIT, and reports
// its quality against the artist weights (per bone, RigNet's rule with the file's first distance
// type, as the trainer's targets): avg L1 of the raw weights and after the evaluator's pruning
// (0.25 of the row maximum, HeterSkinNet Sec. 4.5), the same for uniform weights over the 3
// Euclidean-nearest bones, and how often each binder's fallbacks fired.
//
//   SKINLAB_BINDERS_DATASET=results/datasets/games.h5 SKINLAB_BINDERS_SPLIT=random
//       build/benchmarks/binders_bench --benchmark_out=binders.json --benchmark_out_format=json

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "baselines/bone_heat/bone_heat.hpp"
#include "baselines/geo_voxel/geo_voxel.hpp"
#include "framework/binders/binder.hpp"
#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/data/preprocess.hpp"
#include "framework/eval/weights.hpp"
#include "framework/geometry/closest_point_on_segment.hpp"
#include "benchmarks/synthetic_body.hpp"

namespace {

using namespace skinlab;

using Character = geometry::Character;

// 7 tubes of sides·rings + 2 vertices: 1022, 3038, 5054; 33 bones.
const bench::BodyShape kSizes[] = {{12, 12}, {16, 27}, {20, 36}};

Character make_character(const bench::BodyShape& size) { return bench::make_body(size, "bench"); }

void BM_Bind(benchmark::State& state, const std::string& yaml) {
  const Character c = make_character(kSizes[state.range(0)]);
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(1));
  const auto binder = binder_registry().create(config::Config::parse(yaml).root());
  for (auto _ : state) {
    benchmark::DoNotOptimize(binder->bind(c.mesh, c.skeleton));
  }
  state.counters["vertices"] = c.mesh.num_vertices();
  state.counters["bones"] = static_cast<double>(c.skeleton.bones().size());
  state.counters["threads"] = static_cast<double>(state.range(1));
}

BENCHMARK_CAPTURE(BM_Bind, geo_voxel, std::string("{type: geo_voxel}"))
    ->ArgsProduct({{0, 1, 2}, {1, 2}})
    ->ArgNames({"size", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Bind, bone_heat, std::string("{type: bone_heat}"))
    ->ArgsProduct({{0, 1, 2}, {1, 2}})
    ->ArgNames({"size", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// Uniform weights over the 3 bones nearest by point–segment distance.
Eigen::MatrixXd uniform_three_nearest(const Character& c) {
  const auto bones = c.skeleton.bones();
  const int nb = static_cast<int>(bones.size());
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(c.mesh.num_vertices(), nb);
  std::vector<std::pair<double, int>> d(nb);
  for (int v = 0; v < c.mesh.num_vertices(); ++v) {
    for (int b = 0; b < nb; ++b) {
      d[b] = {geometry::point_segment_distance(c.mesh.V.row(v).transpose(),
                                               c.skeleton.positions.row(bones[b].start),
                                               c.skeleton.positions.row(bones[b].end)),
              b};
    }
    std::sort(d.begin(), d.end());
    for (int i = 0; i < std::min(3, nb); ++i) W(v, d[i].second) = 1.0 / std::min(3, nb);
  }
  return W;
}

/// (raw, pruned) average L1 of P against G (#V×#B each).
std::pair<double, double> average_l1(const Eigen::MatrixXd& P, const Eigen::MatrixXd& G) {
  const double raw = (P - G).cwiseAbs().rowwise().sum().mean();
  data::RowMatrixXd pruned = P;
  eval::prune_rows(pruned, 0.25);
  return {raw, (pruned - G).cwiseAbs().rowwise().sum().mean()};
}

void BM_Dataset(benchmark::State& state, const std::string& yaml) {
  const char* file = std::getenv("SKINLAB_BINDERS_DATASET");
  if (file == nullptr) {
    state.SkipWithError("SKINLAB_BINDERS_DATASET is not set");
    for (auto _ : state) {
    }
    return;
  }
  const data::Dataset dataset = data::read_dataset(file);
  std::vector<int> chosen;
  const char* split = std::getenv("SKINLAB_BINDERS_SPLIT");
  if (split != nullptr) {
    chosen = dataset.splits.at(split).test;
  } else {
    for (int i = 0; i < static_cast<int>(dataset.characters.size()); ++i) chosen.push_back(i);
  }
  const auto binder = binder_registry().create(config::Config::parse(yaml).root());
  double l1 = 0, l1_pruned = 0, u1 = 0, u1_pruned = 0, seconds = 0, vertices = 0;
  int inward_characters = 0, fallback_vertices = 0, fallback_characters = 0, invisible_vertices = 0, snapped_bones = 0;
  for (auto _ : state) {
    for (int index : chosen) {
      const data::PreparedCharacter& p = dataset.characters[index];
      Character c;
      c.mesh.V = p.V;
      c.mesh.F = p.F;
      c.skeleton.names = p.joint_names;
      c.skeleton.positions = p.joints;
      c.skeleton.parents = p.parents;
      const Eigen::MatrixXd G = data::bone_weights(
          p.weights, c.skeleton, p.distances.begin()->second.D.cast<double>());
      double volume = 0;  // signed: > 0 when the faces are oriented outwards
      for (int f = 0; f < c.mesh.num_faces(); ++f) {
        const Eigen::Vector3d a = c.mesh.V.row(c.mesh.F(f, 0)), b = c.mesh.V.row(c.mesh.F(f, 1)),
                              d = c.mesh.V.row(c.mesh.F(f, 2));
        volume += a.dot(b.cross(d)) / 6;
      }
      inward_characters += volume < 0;
      const auto start = std::chrono::steady_clock::now();
      Eigen::MatrixXd W;
      int fallbacks = 0;
      if (const auto* h = dynamic_cast<const baselines::BoneHeat*>(binder.get())) {
        baselines::BoneHeatStats stats;
        W = h->bind(c.mesh, c.skeleton, &stats);
        fallbacks = stats.fallback_vertices;
        invisible_vertices += stats.invisible_vertices;
      } else {
        const auto* g = dynamic_cast<const baselines::GeoVoxel*>(binder.get());
        baselines::GeoVoxelStats stats;
        W = g->bind(c.mesh, c.skeleton, &stats);
        fallbacks = stats.euclidean_vertices;
        snapped_bones += stats.snapped_bones;
      }
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      fallback_vertices += fallbacks;
      fallback_characters += fallbacks > 0;
      vertices += c.mesh.num_vertices();
      const auto [raw, pruned] = average_l1(W, G);
      const auto [uraw, upruned] = average_l1(uniform_three_nearest(c), G);
      l1 += raw, l1_pruned += pruned, u1 += uraw, u1_pruned += upruned;
      if (fallbacks > 0) std::cerr << p.name << ": " << fallbacks << " fallback vertices\n";
      std::cerr << p.name << ": #V " << c.mesh.num_vertices() << " #B " << G.cols() << " volume "
                << volume << " L1 " << raw << " uniform3 " << uraw << "\n";
    }
  }
  const double n = static_cast<double>(chosen.size());
  state.counters["characters"] = n;
  state.counters["mean_vertices"] = vertices / n;
  state.counters["seconds_per_character"] = seconds / n;
  state.counters["avg_l1"] = l1 / n;
  state.counters["avg_l1_pruned"] = l1_pruned / n;
  state.counters["uniform3_avg_l1"] = u1 / n;
  state.counters["uniform3_avg_l1_pruned"] = u1_pruned / n;
  state.counters["fallback_vertices"] = fallback_vertices;
  state.counters["fallback_vertex_fraction"] = fallback_vertices / vertices;
  state.counters["fallback_characters"] = fallback_characters;
  state.counters["inward_characters"] = inward_characters;  // negative signed volume
  state.counters["invisible_vertices"] = invisible_vertices;  // bone_heat: H = 0
  state.counters["snapped_bones"] = snapped_bones;            // geo_voxel: out-of-body bones
}

BENCHMARK_CAPTURE(BM_Dataset, geo_voxel, std::string("{type: geo_voxel}"))
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Dataset, bone_heat, std::string("{type: bone_heat}"))
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  const char* dataset = std::getenv("SKINLAB_BINDERS_DATASET");
  const char* split = std::getenv("SKINLAB_BINDERS_SPLIT");
  benchmark::AddCustomContext("binders_dataset", dataset ? dataset : "(unset: BM_Dataset skipped)");
  benchmark::AddCustomContext("binders_split",
                              split ? std::string(split) + " (test characters)" : "(all)");
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

// Forward and forward+backward of every graph op on a character-sized heterogeneous graph:
// 5,000 vertices, 30,000 one-ring edges (6 per vertex, symmetric), 50,000 geodesic edges (10 per
// vertex), 50 bones (parent → child joints of a random tree), K = 3, feature widths
// 64–256 (HeterSkinNet Sec. 4.2: vertex 256, bone 128, global 512), and DenseGATs' 72 for
// `gat_block` (Sec. 3.4: 8 heads × 8 + 8, the block's own output width). Arguments: {width,
// backward (0/1)}. `BM_EdgeConvPerEdgeReference` is the textbook per-edge formulation (gather,
// concatenate, Linear on #E rows, scatter max) that `edge_conv_max` rewrites exactly.
//
// Steady state is measured: each case runs kWarmUp times untimed first, and glibc keeps freed
// memory in the heap (no mmap per large tensor, no trimming). On this VM, memory the process has
// not touched before costs ~3.5 ms per MB to fault in (0.3 GB/s vs 13 GB/s for reused memory),
// so without this the first iterations of a 256-wide case measure page faults, not the op; a
// training loop reaches the same steady state after a few steps. `SKINLAB_BENCH_NO_MALLOPT=1`
// measures with glibc's defaults.

#include <benchmark/benchmark.h>
#include <malloc.h>
#include <torch/torch.h>

#include <climits>
#include <cstdlib>
#include <fstream>
#include <string>

#include "framework/tensors/threads.hpp"
#include "framework/core/config.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/registry.hpp"
#include "framework/graph/edge_dropout.hpp"
#include "framework/graph/graph_op.hpp"
#include "framework/graph/mlp.hpp"

namespace {

using namespace skinlab;
using namespace skinlab::graph;

constexpr int64_t kVertices = 5000, kBones = 50, kTopK = 3, kBoneWidth = 128;
constexpr int kWarmUp = 5;

const Graph& bench_graph() {
  static const Graph g = [] {
    torch::manual_seed(0);
    Graph g;
    g.num_vertices = kVertices;
    g.num_bones = kBones;
    // one-ring: each vertex linked to 3 nearby indices (a mesh-like band), both directions
    const torch::Tensor v = torch::arange(kVertices).repeat_interleave(3);
    const torch::Tensor offset = torch::randint(1, 40, {kVertices * 3}, torch::kInt64);
    const torch::Tensor u = (v + offset) % kVertices;
    g.one_ring = torch::cat({torch::stack({v, u}, 1), torch::stack({u, v}, 1)});
    g.one_ring = g.one_ring.index_select(0, torch::argsort(g.one_ring.select(1, 0)));
    // geodesic: 10 neighbours within an index window, sorted by receiver
    const torch::Tensor gv = torch::arange(kVertices).repeat_interleave(10);
    g.geodesic = torch::stack(
        {gv, (gv + torch::randint(1, 200, {kVertices * 10}, torch::kInt64)) % kVertices}, 1);
    // random tree of joints: bone j is (random earlier joint, j), 50 in total
    std::vector<std::pair<int64_t, int64_t>> bones;
    for (int64_t j = 1; static_cast<int64_t>(bones.size()) < kBones; ++j) {
      bones.push_back({torch::randint(0, j, {1}).item<int64_t>(), j});
    }
    torch::Tensor bj = torch::empty({kBones, 2}, torch::kInt64);
    for (int64_t b = 0; b < kBones; ++b) {
      bj[b][0] = bones[b].first;
      bj[b][1] = bones[b].second;
    }
    g.skeleton = skeleton_edges(bj);
    g.topk_index = torch::argsort(torch::rand({kVertices, kBones}), /*dim=*/1, /*descending=*/false)
                       .narrow(1, 0, kTopK)
                       .contiguous();
    g.validate("bench");
    return g;
  }();
  return g;
}

void run(benchmark::State& state, const std::string& yaml, int64_t vertex_width,
         int64_t bone_width) {
  torch::manual_seed(1);
  const Graph& g = bench_graph();
  auto op = graph_op_from(config::Config::parse(yaml).root());
  op->build({vertex_width, bone_width, kTopK});
  const bool backward = state.range(1) != 0;
  Features in{torch::randn({kVertices, vertex_width}).requires_grad_(backward),
              torch::randn({kBones, bone_width}).requires_grad_(backward)};
  const auto once = [&] {
    if (backward) {
      const Features out = op->forward(in, g);
      (out.vertex.sum() + out.bone.sum()).backward();
      for (auto& p : op->parameters()) p.mutable_grad().reset();
      in.vertex.mutable_grad().reset();
      in.bone.mutable_grad().reset();
    } else {
      torch::NoGradGuard no_grad;
      const Features out = op->forward(in, g);
      benchmark::DoNotOptimize(out.vertex.data_ptr());
    }
  };
  for (int i = 0; i < kWarmUp; ++i) once();
  for (auto _ : state) once();
  state.counters["params"] = static_cast<double>([&] {
    int64_t n = 0;
    for (auto& p : op->parameters()) n += p.numel();
    return n;
  }());
}

void BM_EdgeConvOneRing(benchmark::State& s) {
  const auto w = std::to_string(s.range(0));
  run(s, "{type: edge_conv, edges: one_ring, mlp: [" + w + "]}", s.range(0), kBoneWidth);
}
void BM_EdgeConvGeodesic(benchmark::State& s) {
  const auto w = std::to_string(s.range(0));
  run(s, "{type: edge_conv, edges: geodesic, mlp: [" + w + "]}", s.range(0), kBoneWidth);
}
void BM_EdgeConvGeodesicTwoLayers(benchmark::State& s) {
  const auto w = std::to_string(s.range(0));
  run(s, "{type: edge_conv, edges: geodesic, mlp: [" + w + ", " + w + "]}", s.range(0), kBoneWidth);
}
void BM_EdgeConvSkeleton(benchmark::State& s) {
  const auto w = std::to_string(s.range(0));
  run(s, "{type: edge_conv, edges: skeleton, mlp: [" + w + "]}", 64, s.range(0));
}
void BM_MeshConv(benchmark::State& s) {
  const auto w = std::to_string(s.range(0));
  run(s, "{type: mesh_conv, edge_mlp: [" + w + "], mlp: [" + w + "]}", s.range(0), kBoneWidth);
}
void BM_V2b(benchmark::State& s) { run(s, "{type: v2b, mlp: [128]}", s.range(0), kBoneWidth); }
void BM_B2v(benchmark::State& s) {
  const auto w = std::to_string(s.range(0));
  run(s, "{type: b2v, mlp: [" + w + "]}", s.range(0), kBoneWidth);
}
/// NeuroSkinning's graph convolution unit at its first unit's hidden width (x ‖ h ‖ pool(h)).
void BM_GconvPool(benchmark::State& s) {
  const auto w = std::to_string(s.range(0));
  run(s, "{type: gconv_pool, mlp: [" + w + "]}", s.range(0), kBoneWidth);
}
/// DenseGATs' GAT block (Sec. 3.4: 8 heads of 8, β = 0.125, tanhshrink; 72 → 72) on the
/// one-ring edges, self-loops included. DenseGATs has 3 × 6 + 2 such blocks, whose inputs widen
/// along a dense module (Eq. 5).
void BM_GatBlock(benchmark::State& s) {
  run(s, "{type: gat_block, heads: 8, hidden: 8, beta: 0.125}", s.range(0), kBoneWidth);
}
/// The mesh-sequence BiLSTM's mesh convolution (Eq. 2) and its transpose at the paper's feature
/// width of 9 (ACAP) and a hidden width.
void BM_MeanConv(benchmark::State& s) {
  run(s, "{type: mean_conv, width: " + std::to_string(s.range(0)) + "}", s.range(0), kBoneWidth);
}
void BM_MeanConvTranspose(benchmark::State& s) {
  run(s, "{type: mean_conv, transpose: true, width: " + std::to_string(s.range(0)) + "}",
      s.range(0), kBoneWidth);
}
void BM_GlobalPool(benchmark::State& s) {
  run(s, "{type: global_pool, vertex_mlp: [512], bone_mlp: [512]}", s.range(0), kBoneWidth);
}

/// Per-edge EdgeConv: MLP(x_i ‖ x_i − x_j) on every edge (+ self-loops), then scatter max.
void BM_EdgeConvPerEdgeReference(benchmark::State& state) {
  torch::manual_seed(1);
  const Graph& g = bench_graph();
  const int64_t w = state.range(0);
  const bool backward = state.range(1) != 0;
  Mlp mlp(2 * w, MlpOptions{{w}});
  const torch::Tensor x = torch::randn({kVertices, w}).requires_grad_(backward);
  const torch::Tensor self = torch::arange(kVertices).view({-1, 1}).expand({kVertices, 2});
  const torch::Tensor edges = torch::cat({g.geodesic, self});
  const torch::Tensor i = edges.select(1, 0), j = edges.select(1, 1);
  for (int iteration = -kWarmUp; iteration < 0 || state.KeepRunning(); ++iteration) {
    std::unique_ptr<torch::NoGradGuard> guard;
    if (!backward) guard = std::make_unique<torch::NoGradGuard>();
    const torch::Tensor xi = x.index_select(0, i), xj = x.index_select(0, j);
    const torch::Tensor m = mlp->forward(torch::cat({xi, xi - xj}, 1));
    const torch::Tensor out =
        torch::zeros({kVertices, w})
            .scatter_reduce(0, i.view({-1, 1}).expand({i.size(0), w}), m, "amax", false);
    if (backward) {
      out.sum().backward();
      for (auto& p : mlp->parameters()) p.mutable_grad().reset();
      x.mutable_grad().reset();
    } else {
      benchmark::DoNotOptimize(out.data_ptr());
    }
  }
}

/// HeterSkinNet's head MLP (Sec. 4.2: [1024, 512, K] on vertex local 256 ‖ K = 3 candidate bones'
/// local 128 ‖ global 512 + 512), forward+backward as in training. Argument {split}: 1 is
/// `Mlp::forward_gathered` (layer 0 split by weight blocks), 0 its peer, the MLP on the #V×1664
/// concatenation, which is what training computed before.
void BM_GatheredMlpHead(benchmark::State& state) {
  torch::manual_seed(3);
  const Graph& g = bench_graph();
  const bool split = state.range(0) != 0;
  constexpr int64_t kOwn = 256, kShared = 1024;
  Mlp mlp(kOwn + kTopK * kBoneWidth + kShared, MlpOptions{{1024, 512, kTopK}, false, 0.0});
  const torch::Tensor own = torch::randn({kVertices, kOwn}).requires_grad_(true);
  const torch::Tensor table = torch::randn({kBones, kBoneWidth}).requires_grad_(true);
  const torch::Tensor shared = torch::randn({1, kShared}).requires_grad_(true);
  for (int iteration = -kWarmUp; iteration < 0 || state.KeepRunning(); ++iteration) {
    torch::Tensor out;
    if (split) {
      out = mlp->forward_gathered(own, table, g.topk_index, shared);
    } else {
      out = mlp->forward(torch::cat(
          {own, table.index_select(0, g.topk_index.reshape({-1})).view({kVertices, -1}),
           shared.expand({kVertices, kShared})},
          1));
    }
    out.sum().backward();
    for (auto& p : mlp->parameters()) p.mutable_grad().reset();
    for (const torch::Tensor& t : {own, table, shared}) t.mutable_grad().reset();
  }
}

void BM_DropEdges(benchmark::State& state) {
  torch::manual_seed(2);
  const Graph& g = bench_graph();
  const EdgeDropoutOptions options;  // p = 0.85 on one_ring and geodesic
  for (auto _ : state) {
    const Graph dropped = drop_edges(g, options);
    benchmark::DoNotOptimize(dropped.geodesic.data_ptr());
  }
}

#define SKINLAB_GRAPH_BENCH(fn)          \
  BENCHMARK(fn)                          \
      ->ArgsProduct({{64, 256}, {0, 1}}) \
      ->ArgNames({"width", "backward"})  \
      ->Unit(benchmark::kMillisecond)

SKINLAB_GRAPH_BENCH(BM_EdgeConvOneRing);
SKINLAB_GRAPH_BENCH(BM_EdgeConvGeodesic);
SKINLAB_GRAPH_BENCH(BM_EdgeConvGeodesicTwoLayers);
SKINLAB_GRAPH_BENCH(BM_EdgeConvPerEdgeReference);
SKINLAB_GRAPH_BENCH(BM_EdgeConvSkeleton);
SKINLAB_GRAPH_BENCH(BM_MeshConv);
SKINLAB_GRAPH_BENCH(BM_V2b);
SKINLAB_GRAPH_BENCH(BM_B2v);
SKINLAB_GRAPH_BENCH(BM_GconvPool);
SKINLAB_GRAPH_BENCH(BM_GlobalPool);
BENCHMARK(BM_GatBlock)
    ->ArgsProduct({{72}, {0, 1}})
    ->ArgNames({"width", "backward"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MeanConv)
    ->ArgsProduct({{9, 64}, {0, 1}})
    ->ArgNames({"width", "backward"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MeanConvTranspose)
    ->ArgsProduct({{9, 64}, {0, 1}})
    ->ArgNames({"width", "backward"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GatheredMlpHead)->Arg(0)->Arg(1)->ArgName("split")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DropEdges)->Unit(benchmark::kMicrosecond);

}  // namespace

/// The BLAS library actually mapped into the process (Debian's libtorch calls libblas.so.3, which
/// the alternatives system points at the reference BLAS, OpenBLAS, BLIS, ...). Matrix products
/// dominate most ops, so this decides the numbers more than anything in the ops.
std::string loaded_blas() {
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    const auto slash = line.find('/');
    if (slash != std::string::npos && line.find("blas", slash) != std::string::npos) {
      return line.substr(slash);
    }
  }
  return "unknown";
}

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (std::getenv("SKINLAB_BENCH_NO_MALLOPT") == nullptr) {
    mallopt(M_MMAP_MAX, 0);              // large tensors from the heap, reused when freed
    mallopt(M_TRIM_THRESHOLD, INT_MAX);  // keep freed heap (up to 2 GiB) instead of trimming it
    benchmark::AddCustomContext("malloc", "M_MMAP_MAX=0, M_TRIM_THRESHOLD=INT_MAX");
  }
  // Every hardware thread, as `skinlab train` uses by default; SKINLAB_THREADS overrides.
  const char* threads = std::getenv("SKINLAB_THREADS");
  skinlab::set_torch_threads(threads ? std::atoi(threads) : 0);
  benchmark::AddCustomContext("blas", loaded_blas());
  benchmark::AddCustomContext("torch_threads", std::to_string(torch::get_num_threads()));
  benchmark::AddCustomContext("graph",
                              "5000 vertices, 30000 one-ring, 50000 geodesic, 50 bones, K=3");
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

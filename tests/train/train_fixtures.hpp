#pragma once
// Shared by the training tests: small synthetic characters (a tube around a branching joint
// chain, with a duplicated seam so merging and the vertex map are exercised, subdivided once by
// the preprocessing), a dataset file of them with a split, and experiment configs for the
// test-only model `test_vertex_mlp` (registered in trainer_test.cpp).

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "framework/data/source.hpp"
#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/data/preprocess.hpp"
#include "framework/distances/distance.hpp"
#include "framework/geometry/skin_weights.hpp"

namespace skinlab::testing {

/// The source-frame transform of character `index`: scale 2, shifted, so the normalisation is
/// not the identity and mapping back to the source frame is tested.
inline constexpr double kSourceScale = 2.0;
inline Eigen::Vector3d source_offset(int index) { return {0.3 + 0.1 * index, -1.0, 0.2}; }

/// A tube of `rings` rings of `segments` vertices (+1 duplicated seam vertex per ring) around
/// the chain root → spine → neck → head with an arm branching at the spine, in a source frame of
/// scale kSourceScale. Weights blend along the height with a per-character shift; the arm takes
/// the weight of vertices on its side.
inline datasets::SourceCharacter tube_character(int index) {
  const int rings = 8 + index % 3, segments = 8;
  const double radius = 0.12 + 0.02 * (index % 4);
  const double shift = 0.04 * ((index * 7) % 5) - 0.08;
  geometry::Character c;
  c.name = "tube_" + std::to_string(index);
  // Joints (normalised-ish frame before the source transform): heights of the chain.
  const std::vector<double> height = {0.05, 0.35 + shift, 0.65 + shift, 0.95};
  c.skeleton.names = {"root", "spine", "neck", "head", "left arm"};  // a name with a space
  c.skeleton.parents = {-1, 0, 1, 2, 1};
  Eigen::MatrixXd J(5, 3);
  J << 0, height[0], 0, 0, height[1], 0, 0, height[2], 0, 0, height[3], 0, 0.2, height[1] + 0.1, 0;
  const int per_ring = segments + 1;
  Eigen::MatrixXd V(rings * per_ring, 3);
  std::vector<Eigen::Triplet<double>> w;
  for (int r = 0; r < rings; ++r) {
    const double y = static_cast<double>(r) / (rings - 1);
    for (int s = 0; s <= segments; ++s) {
      const double a = 2 * M_PI * (s % segments) / segments;  // s = segments duplicates s = 0
      const int v = r * per_ring + s;
      V.row(v) << radius * std::cos(a), y, radius * std::sin(a);
      // Height blend between the two chain joints around y.
      std::vector<double> jw(5, 0.0);
      if (y <= height[0]) {
        jw[0] = 1;
      } else if (y >= height[3]) {
        jw[3] = 1;
      } else {
        int k = 0;
        while (y > height[k + 1]) ++k;
        const double t = (y - height[k]) / (height[k + 1] - height[k]);
        jw[k] = 1 - t;
        jw[k + 1] = t;
      }
      // The arm takes half of the spine's weight on the +x side.
      if (std::cos(a) > 0.5 && jw[1] > 0) {
        jw[4] = 0.5 * jw[1];
        jw[1] *= 0.5;
      }
      for (int j = 0; j < 5; ++j)
        if (jw[j] > 0) w.emplace_back(v, j, jw[j]);
    }
  }
  Eigen::MatrixXi F(2 * (rings - 1) * segments, 3);
  int f = 0;
  for (int r = 0; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const int a = r * per_ring + s, b = a + 1, cc = a + per_ring, d = cc + 1;
      F.row(f++) << a, b, d;
      F.row(f++) << a, d, cc;
    }
  }
  // Into the source frame.
  const Eigen::RowVector3d offset = source_offset(index).transpose();
  V = (V * kSourceScale).rowwise() + offset;
  J = (J * kSourceScale).rowwise() + offset;
  c.mesh.V = V;
  c.mesh.F = F;
  c.skeleton.positions = J;
  c.weights.resize(V.rows(), 5);
  c.weights.setFromTriplets(w.begin(), w.end());
  c.weights.makeCompressed();
  c.validate();
  datasets::SourceCharacter s;
  s.character = c;
  s.source = "test";
  s.path = c.name + ".obj";
  s.licence = "CC0-1.0";
  s.attribution = "skinlab tests";
  s.skeleton = "tube";
  return s;
}

/// Preprocessed as `skinlab prepare` does, with the euclidean distance and K = `top_k` (capped at
/// the tube's 6 bones); the ~80-vertex tubes are subdivided once (min_vertices 100).
inline data::PreparedCharacter prepared_tube(int index, int top_k = 3) {
  const auto euclidean = distance_registry().create(config::Config::parse("type: euclidean").root());
  data::PreprocessOptions options;
  options.min_vertices = 100;
  options.max_vertices = 2000;
  options.top_k = top_k;
  return data::preprocess(tube_character(index), {{"euclidean", euclidean}}, options);
}

/// A dataset file of `train + val + test` tubes with split "random" (in that order).
inline void write_tube_dataset(const std::filesystem::path& file, int train, int val, int test) {
  data::Dataset d;
  data::Split split;
  for (int i = 0; i < train + val + test; ++i) {
    d.characters.push_back(prepared_tube(i));
    (i < train ? split.train : i < train + val ? split.val : split.test).push_back(i);
  }
  d.splits["random"] = split;
  d.preparation = "test";
  data::write_dataset(file, d);
}

/// An experiment config for the tubes in `dataset`, results under `results`.
inline std::string tube_config(const std::filesystem::path& dataset,
                               const std::filesystem::path& results, const std::string& extra = "") {
  return "experiment: tubes\n"
         "seed: 7\n"
         "results_dir: " + results.string() + "\n"
         "model: {type: test_vertex_mlp, hidden: 16, top_k: 3, dropout: 0.2}\n"
         "losses:\n"
         "  - {type: kl, weight: 1.0}\n"
         "  - {type: laplacian_smoothing, weight: 0.4}\n"
         "data: {file: " + dataset.string() + ", split: random, distance: euclidean}\n"
         "train: {epochs: 4, lr: 1.0e-2, weight_decay: 1.0e-4, patience: 0, log_every: 2}\n" +
         extra;
}

}  // namespace skinlab::testing

#pragma once
// Shared by the binder tests: synthetic characters built from closed tubes (tests/shapes), row checks, and the Minetest player prepared as the
// pipeline prepares it (normalised, merged, subdivided, artist weights per bone).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "framework/binders/binder.hpp"
#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/preprocess.hpp"
#include "framework/geometry/closest_point_on_segment.hpp"
#include "tests/data/data_fixtures.hpp"
#include "tests/shapes/tube.hpp"

namespace skinlab::testing {

/// A vertical tube (x = z = 0, y from 0.05 to 0.95, radius 0.06, 16 sides, 37 rings: a vertex
/// ring every 2.5 cm) around a 3-bone chain; bones() = [j0→j1, j1→j2, j2→j3, helper j3].
struct Chain {
  static constexpr int kSides = 16, kRings = 37;
  geometry::Mesh mesh;
  geometry::Skeleton skeleton;
  /// Vertex index of ring i, side j.
  static int vertex(int i, int j) { return i * kSides + j; }
  /// y of ring i.
  static double ring_y(int i) { return 0.05 + 0.9 * i / (kRings - 1); }
};

inline Chain chain() {
  Chain c;
  c.mesh = TubeBuilder().tube({0, 0.05, 0}, {0, 0.95, 0}, 0.06, Chain::kSides, Chain::kRings).build();
  Eigen::MatrixXd J(4, 3);
  J << 0, 0.1, 0, 0, 0.37, 0, 0, 0.63, 0, 0, 0.9, 0;
  c.skeleton = geometry::Skeleton::from_parent_names({"j0", "j1", "j2", "j3"}, J,
                                                     {"", "j0", "j1", "j2"}, "chain");
  return c;
}

/// Two parallel vertical fingers on a horizontal palm (three intersecting closed tubes): finger
/// A (x = −0.15, radius 0.08) and finger B (x = 0, radius 0.02); their surfaces are 5 cm apart.
/// Skeleton: root in the palm → a0 → a1 up finger A, root → b0 → b1 up finger B. bones() =
/// [root→a0, root→b0, a0→a1, helper a1, b0→b1, helper b1]. A vertex on A's inner side is
/// closer in a straight line to B's bone (7 cm) than to A's (8 cm).
struct Fingers {
  static constexpr int kBoneA = 2, kBoneB = 4;  // a0→a1, b0→b1
  /// The vertex of finger A's ring 14 (y ≈ 0.757) facing finger B (+x): (−0.07, 0.757, 0).
  int inner_a() const { return first_a + 14 * 16; }
  geometry::Mesh mesh;
  geometry::Skeleton skeleton;
  int first_a = 0;  ///< first vertex of finger A's tube
};

inline Fingers fingers() {
  Fingers f;
  TubeBuilder t;
  t.tube({-0.3, 0.45, 0}, {0.15, 0.45, 0}, 0.07, 16, 19);
  f.first_a = t.num_vertices();
  t.tube({-0.15, 0.42, 0}, {-0.15, 0.95, 0}, 0.08, 16, 23);
  t.tube({0, 0.42, 0}, {0, 0.95, 0}, 0.02, 8, 23);
  f.mesh = t.build();
  Eigen::MatrixXd J(5, 3);
  J << 0, 0.45, 0, -0.15, 0.55, 0, -0.15, 0.9, 0, 0, 0.55, 0, 0, 0.9, 0;
  f.skeleton = geometry::Skeleton::from_parent_names({"root", "a0", "a1", "b0", "b1"}, J,
                                                     {"", "root", "a0", "root", "b0"}, "fingers");
  const auto bones = f.skeleton.bones();
  EXPECT_EQ(f.skeleton.names[bones[Fingers::kBoneA].end], "a1");
  EXPECT_EQ(f.skeleton.names[bones[Fingers::kBoneB].end], "b1");
  return f;
}

/// Every entry ≥ 0, every row sums to 1 (1e-9), the expected shape.
inline void expect_valid_rows(const Eigen::MatrixXd& W, int rows, int cols) {
  ASSERT_EQ(W.rows(), rows);
  ASSERT_EQ(W.cols(), cols);
  ASSERT_TRUE(W.allFinite());
  EXPECT_GE(W.minCoeff(), 0.0);
  for (int v = 0; v < W.rows(); ++v) {
    ASSERT_NEAR(W.row(v).sum(), 1.0, 1e-9) << "row " << v;
  }
}

/// The chain tube and its triangulation are symmetric under x → −x (side j ↔ side kSides/2 − j):
/// so must the weights be, to 1e-6.
inline void expect_mirror_symmetric(const Eigen::MatrixXd& W) {
  for (int i = 0; i < Chain::kRings; ++i) {
    for (int j = 0; j < Chain::kSides; ++j) {
      const int mirror = (Chain::kSides / 2 - j + Chain::kSides) % Chain::kSides;
      for (Eigen::Index b = 0; b < W.cols(); ++b) {
        EXPECT_NEAR(W(Chain::vertex(i, j), b), W(Chain::vertex(i, mirror), b), 1e-6)
            << "ring " << i << " side " << j << " bone " << b;
      }
    }
  }
}

inline std::shared_ptr<binders::Binder> make_binder(const std::string& yaml) {
  return binder_registry().create(config::Config::parse(yaml, "test.yaml").root());
}

/// The Minetest player as the pipeline prepares it (normalised, 1K–5K vertices), with its
/// artist weights per bone (RigNet's rule, data::bone_weights with Euclidean distances).
struct PreparedPlayer {
  geometry::Mesh mesh;
  geometry::Skeleton skeleton;
  Eigen::MatrixXd weights;  ///< #V×#B
};

inline PreparedPlayer prepared_player() {
  const auto euclid = distance_registry().create(config::Config::parse("type: euclidean").root());
  const data::PreparedCharacter c = data::preprocess(minetest_player(), {{"euclidean", euclid}});
  PreparedPlayer p;
  p.mesh.V = c.V;
  p.mesh.F = c.F;
  p.skeleton.names = c.joint_names;
  p.skeleton.positions = c.joints;
  p.skeleton.parents = c.parents;
  p.weights = data::bone_weights(c.weights, p.skeleton, euclid->compute(p.mesh, p.skeleton));
  return p;
}

/// (1/#V) Σ_v Σ_b |P − G| (HeterSkinNet's L1-norm before pruning).
inline double average_l1(const Eigen::MatrixXd& P, const Eigen::MatrixXd& G) {
  return (P - G).cwiseAbs().rowwise().sum().mean();
}

/// Uniform weights over the 3 bones nearest to each vertex by point–segment distance: the bound
/// a binder must beat on a real character.
inline Eigen::MatrixXd uniform_three_nearest(const geometry::Mesh& mesh,
                                             const geometry::Skeleton& skeleton) {
  const auto bones = skeleton.bones();
  const int nb = static_cast<int>(bones.size());
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(mesh.num_vertices(), nb);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    std::vector<std::pair<double, int>> d;
    for (int b = 0; b < nb; ++b) {
      d.emplace_back(geometry::point_segment_distance(mesh.V.row(v).transpose(),
                                                      skeleton.positions.row(bones[b].start),
                                                      skeleton.positions.row(bones[b].end)),
                     b);
    }
    std::sort(d.begin(), d.end());
    const int k = std::min(3, nb);
    for (int i = 0; i < k; ++i) W(v, d[i].second) = 1.0 / k;
  }
  return W;
}

}  // namespace skinlab::testing

// volumetric_geodesic: the AABB-tree + multi-source-Dijkstra path against a brute-force reference
// (every triangle tested against every segment, all-pairs Floyd–Warshall), plus known answers on
// small closed meshes built here from voxels.

#include "framework/distances/volumetric_geodesic.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Eigen/Geometry>
#include <ostream>

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "framework/core/registry.hpp"
#include "tests/test_util.hpp"

namespace skinlab::distances {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using geometry::Mesh;
using geometry::Skeleton;
using skinlab::testing::expect_error;
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- meshes -------------------------------------------------------------------------------------

/// Closed surface of a set of unit voxels (integer cell coordinates), scaled by `h`, with shared
/// corner vertices; each vertex is then moved by up to `jitter`·h (seeded) so that no segment in
/// a test passes exactly through an edge or vertex, where an exact and a floating-point
/// intersection test may legitimately disagree.
Mesh voxel_mesh(const std::set<std::array<int, 3>>& cells, double h, double jitter,
                unsigned seed = 1) {
  std::map<std::array<int, 3>, int> index;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> faces;
  const auto vertex = [&](std::array<int, 3> c) {
    auto [it, inserted] = index.try_emplace(c, static_cast<int>(vertices.size()));
    if (inserted) vertices.emplace_back(c[0] * h, c[1] * h, c[2] * h);
    return it->second;
  };
  for (const auto& c : cells) {
    for (int axis = 0; axis < 3; ++axis) {
      for (int side : {0, 1}) {
        auto n = c;
        n[axis] += side ? 1 : -1;
        if (cells.count(n)) continue;
        const int u = (axis + 1) % 3, w = (axis + 2) % 3;
        std::array<int, 4> q;
        for (int k = 0; k < 4; ++k) {
          auto p = c;
          p[axis] += side;
          p[u] += (k == 1 || k == 2);
          p[w] += (k >= 2);
          q[k] = vertex(p);
        }
        faces.emplace_back(q[0], q[1], q[2]);
        faces.emplace_back(q[0], q[2], q[3]);
      }
    }
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> noise(-jitter * h, jitter * h);
  Mesh mesh;
  mesh.V.resize(vertices.size(), 3);
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) mesh.V(i, k) = vertices[i][k] + noise(rng);
  }
  mesh.F.resize(faces.size(), 3);
  for (std::size_t i = 0; i < faces.size(); ++i) mesh.F.row(i) = faces[i].transpose();
  return mesh;
}

std::set<std::array<int, 3>> box_cells(std::array<int, 3> lo, std::array<int, 3> hi) {
  std::set<std::array<int, 3>> out;
  for (int x = lo[0]; x < hi[0]; ++x)
    for (int y = lo[1]; y < hi[1]; ++y)
      for (int z = lo[2]; z < hi[2]; ++z) out.insert({x, y, z});
  return out;
}

/// U-shaped closed tube: two 2×2-cell arms 10 cells high, x ∈ [0, 2) and [5, 7), joined by a
/// base at z ∈ [0, 2). With h = 0.05 the arms are 0.1 m thick, 0.15 m apart, 0.5 m high.
std::set<std::array<int, 3>> u_cells() {
  auto cells = box_cells({0, 0, 0}, {2, 2, 10});
  for (const auto& c : box_cells({5, 0, 0}, {7, 2, 10})) cells.insert(c);
  for (const auto& c : box_cells({2, 0, 0}, {5, 2, 2})) cells.insert(c);
  return cells;
}

Mesh merge(const Mesh& a, const Mesh& b) {
  Mesh m;
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, b.V;
  m.F.resize(a.F.rows() + b.F.rows(), 3);
  m.F << a.F, (b.F.array() + static_cast<int>(a.V.rows())).matrix();
  return m;
}

/// Chain skeleton j0 → j1 → … (the last joint is a leaf, so bones() ends with a helper bone).
Skeleton chain(const std::vector<Eigen::Vector3d>& joints) {
  std::vector<std::string> names, parents;
  Eigen::MatrixXd positions(joints.size(), 3);
  for (std::size_t j = 0; j < joints.size(); ++j) {
    names.push_back("j" + std::to_string(j));
    parents.push_back(j == 0 ? "" : names[j - 1]);
    positions.row(j) = joints[j].transpose();
  }
  return Skeleton::from_parent_names(names, positions, parents, "test chain");
}

VolumetricGeodesic make(const std::string& yaml = "{}") {
  return VolumetricGeodesic(
      VolumetricGeodesic::Options::from(config::Config::parse(yaml, "test.yaml").root()));
}

// ---- naive reference ----------------------------------------------------------------------------

/// Plain floating-point segment–triangle test (Möller–Trumbore restricted to t ∈ [0, 1]).
bool segment_hits_triangle(const Eigen::Vector3d& o, const Eigen::Vector3d& e,
                           const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                           const Eigen::Vector3d& c) {
  const Eigen::Vector3d d = e - o, ab = b - a, ac = c - a;
  const Eigen::Vector3d pv = d.cross(ac);
  const double det = ab.dot(pv);
  if (std::abs(det) < 1e-300) return false;  // parallel (or zero-area) triangle
  const Eigen::Vector3d tv = o - a;
  const double u = tv.dot(pv) / det;
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d qv = tv.cross(ab);
  const double v = d.dot(qv) / det;
  if (v < 0 || u + v > 1) return false;
  const double t = ac.dot(qv) / det;
  return t >= 0 && t <= 1;
}

Eigen::Vector3d closest_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                   const Eigen::Vector3d& b) {
  const double l2 = (b - a).squaredNorm();
  if (l2 < 1e-8) return a;
  return a + std::clamp((p - a).dot(b - a) / l2, 0.0, 1.0) * (b - a);
}

/// The definition, computed the slow way with the same options as `o`.
Eigen::MatrixXd reference(const Mesh& mesh, const Skeleton& skeleton,
                          const VolumetricGeodesic::Options& o) {
  const auto bones = skeleton.bones();
  const int nv = mesh.num_vertices(), nb = static_cast<int>(bones.size());
  const auto V = [&](int i) -> Eigen::Vector3d { return mesh.V.row(i).transpose(); };

  // All-pairs surface geodesic on mesh edges.
  Eigen::MatrixXd G = Eigen::MatrixXd::Constant(nv, nv, kInf);
  for (int i = 0; i < nv; ++i) G(i, i) = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      G(a, b) = G(b, a) = (V(a) - V(b)).norm();
    }
  }
  for (int k = 0; k < nv; ++k)
    for (int i = 0; i < nv; ++i)
      for (int j = 0; j < nv; ++j) G(i, j) = std::min(G(i, j), G(i, k) + G(k, j));

  Eigen::MatrixXd D(nv, nb);
  for (int b = 0; b < nb; ++b) {
    const Eigen::Vector3d a = skeleton.positions.row(bones[b].start).transpose();
    const Eigen::Vector3d e = skeleton.positions.row(bones[b].end).transpose();
    std::vector<Eigen::Vector3d> samples;
    if ((e - a).squaredNorm() < 1e-8) {
      samples = {a};
    } else {
      for (int s = 0; s < o.samples_per_bone; ++s) {
        const double u = static_cast<double>(s) / (o.samples_per_bone - 1);
        samples.push_back((1 - u) * a + u * e);
      }
    }
    std::vector<double> direct(nv, kInf), euclid(nv);
    for (int v = 0; v < nv; ++v) {
      euclid[v] = (V(v) - closest_on_segment(V(v), a, e)).norm();
      auto origins = samples;
      origins.push_back(closest_on_segment(V(v), a, e));
      for (const auto& origin : origins) {
        const double length = (V(v) - origin).norm();
        bool blocked = false;
        if (length > o.ray_epsilon) {
          const Eigen::Vector3d stop = V(v) - (V(v) - origin) * (o.ray_epsilon / length);
          for (int f = 0; f < mesh.num_faces() && !blocked; ++f) {
            blocked = segment_hits_triangle(origin, stop, V(mesh.F(f, 0)), V(mesh.F(f, 1)),
                                            V(mesh.F(f, 2)));
          }
        }
        if (!blocked) direct[v] = std::min(direct[v], length);
      }
    }
    if (o.filter_far_visible) {
      std::vector<double> visible;
      for (double d : direct)
        if (d < kInf) visible.push_back(d);
      if (!visible.empty()) {
        std::sort(visible.begin(), visible.end());
        const double rank = o.filter_percentile / 100 * (visible.size() - 1);
        const std::size_t lo = static_cast<std::size_t>(rank);
        const std::size_t hi = std::min(lo + 1, visible.size() - 1);
        const double q = visible[lo] + (visible[hi] - visible[lo]) * (rank - lo);
        for (double& d : direct)
          if (d > o.filter_factor * q) d = kInf;
      }
    }
    for (int v = 0; v < nv; ++v) {
      double d = direct[v];
      if (direct[v] == kInf) {
        for (int u = 0; u < nv; ++u) d = std::min(d, direct[u] + G(u, v));
      }
      if (d == kInf) {  // unreached: v's component has no visible vertex
        if (o.unreached == "euclidean") {
          d = o.unreached_penalty + euclid[v];
        } else {
          int seed = -1;
          for (int u = 0; u < nv; ++u) {
            if (G(u, v) < kInf && (seed < 0 || euclid[u] < euclid[seed])) seed = u;
          }
          d = o.unreached_penalty + euclid[seed] + G(seed, v);
        }
      }
      D(v, b) = d;
    }
  }
  return D;
}

void expect_allclose(const Eigen::MatrixXd& actual, const Eigen::MatrixXd& expected) {
  ASSERT_EQ(actual.rows(), expected.rows());
  ASSERT_EQ(actual.cols(), expected.cols());
  int mismatches = 0;
  for (int b = 0; b < actual.cols(); ++b) {
    for (int v = 0; v < actual.rows(); ++v) {
      if (std::abs(actual(v, b) - expected(v, b)) > 1e-9 * (1 + std::abs(expected(v, b)))) {
        if (++mismatches <= 5) {
          ADD_FAILURE() << "vertex " << v << " bone " << b << ": " << actual(v, b)
                        << " != reference " << expected(v, b);
        }
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
}

// ---- fast path vs reference ---------------------------------------------------------------------

struct Case {
  std::string name;
  std::string options;
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.name << " " << c.options; }

class VolumetricGeodesicReference : public ::testing::TestWithParam<Case> {};

TEST_P(VolumetricGeodesicReference, MatchesNaiveOnBoxWithChain) {
  // 0.15 × 0.15 × 0.6 m closed box (146 vertices), a 4-bone chain near its axis, off-centre so
  // no ray is symmetric.
  const Mesh mesh = voxel_mesh(box_cells({0, 0, 0}, {3, 3, 12}), 0.05, 0.02);
  const Skeleton skeleton = chain({{0.071, 0.078, 0.04},
                                   {0.083, 0.069, 0.19},
                                   {0.062, 0.081, 0.33},
                                   {0.079, 0.073, 0.47},
                                   {0.068, 0.077, 0.56}});
  const auto distance = make(GetParam().options);
  const Eigen::MatrixXd D = distance.compute(mesh, skeleton);
  EXPECT_EQ(D.cols(), 5);  // 4 bones and the helper bone of the leaf
  expect_allclose(D, reference(mesh, skeleton, distance.options()));
}

TEST_P(VolumetricGeodesicReference, MatchesNaiveOnUTubeWithDisconnectedPart) {
  // Occlusion between the arms, a bent chain whose projections are occluded near the base,
  // a floating cube that no bone sees, and a bone leaving the mesh.
  const Mesh u = voxel_mesh(u_cells(), 0.05, 0.02, 7);
  const Mesh cube = voxel_mesh(box_cells({10, 0, 4}, {12, 2, 6}), 0.05, 0.02, 9);
  const Mesh mesh = merge(u, cube);
  const Skeleton skeleton = chain({{0.051, 0.048, 0.42},
                                   {0.047, 0.052, 0.06},
                                   {0.31, 0.049, 0.055},
                                   {0.298, 0.051, 0.43},
                                   {0.30, 0.05, 0.62}});  // last bone pokes out of the arm
  const auto distance = make(GetParam().options);
  const Eigen::MatrixXd D = distance.compute(mesh, skeleton);
  expect_allclose(D, reference(mesh, skeleton, distance.options()));
}

INSTANTIATE_TEST_SUITE_P(
    Options, VolumetricGeodesicReference,
    ::testing::Values(Case{"rignet_defaults", "{}"},
                      Case{"no_filter", "{filter_far_visible: false, samples_per_bone: 4}"},
                      Case{"euclidean_fallback", "{unreached: euclidean, unreached_penalty: 0.5}"},
                      Case{"projection_and_ends", "{samples_per_bone: 2, filter_percentile: 50}"}),
    [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

// ---- known answers ------------------------------------------------------------------------------

TEST(VolumetricGeodesic, VisibleVertexInClosedTubeGetsItsEuclideanDistance) {
  // An exact (unjittered) box is convex, so a bone inside sees every vertex from its
  // projection: D is the point-to-segment distance, RigNet's pts2line.
  const Mesh mesh = voxel_mesh(box_cells({0, 0, 0}, {3, 3, 10}), 0.05, 0.0);
  const Skeleton skeleton = chain({{0.07, 0.08, 0.05}, {0.075, 0.07, 0.3}, {0.08, 0.075, 0.45}});
  const auto bones = skeleton.bones();
  const Eigen::MatrixXd D = make("{filter_far_visible: false}").compute(mesh, skeleton);
  ASSERT_EQ(D.rows(), mesh.num_vertices());
  ASSERT_EQ(D.cols(), 3);
  for (int b = 0; b < 3; ++b) {
    const Eigen::Vector3d a = skeleton.positions.row(bones[b].start).transpose();
    const Eigen::Vector3d e = skeleton.positions.row(bones[b].end).transpose();
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      const Eigen::Vector3d p = mesh.V.row(v).transpose();
      EXPECT_NEAR(D(v, b), (p - closest_on_segment(p, a, e)).norm(), 1e-12)
          << "vertex " << v << " bone " << b;
    }
  }
  // With RigNet's filter the nearest visible vertices keep exactly that distance, the far ones
  // go round the surface and can only get longer.
  const Eigen::MatrixXd F = make().compute(mesh, skeleton);
  EXPECT_TRUE((F.array() >= D.array() - 1e-12).all());
  EXPECT_GT((F.array() == D.array()).count(), D.size() / 10);
}

TEST(VolumetricGeodesic, OtherArmOfUTubeIsOccluded) {
  const Mesh mesh = voxel_mesh(u_cells(), 0.05, 0.0);
  // One bone up the middle of the left arm (x ∈ [0, 0.1]).
  const Skeleton skeleton = chain({{0.05, 0.05, 0.15}, {0.05, 0.05, 0.45}});
  const Eigen::MatrixXd D = make("{filter_far_visible: false}").compute(mesh, skeleton);
  int checked = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d p = mesh.V.row(v).transpose();
    const double euclid =
        (p - closest_on_segment(p, {0.05, 0.05, 0.15}, {0.05, 0.05, 0.45})).norm();
    EXPECT_GE(D(v, 0), euclid - 1e-12);
    if (p.x() > 0.24 && p.z() > 0.2) {  // the right arm, above the base: walls in between
      ++checked;
      // Down the left arm, across the base, up the right arm: far longer than straight across.
      EXPECT_GT(D(v, 0), euclid + 0.1) << "vertex " << v << " at " << p.transpose();
    }
    if (p.x() < 0.11 && p.z() > 0.2 && p.z() < 0.4) {  // the bone's own arm: seen directly
      EXPECT_NEAR(D(v, 0), euclid, 1e-12) << "vertex " << v;
    }
  }
  EXPECT_GT(checked, 10);
}

TEST(VolumetricGeodesic, DisconnectedPartAndOutsideBoneAreFinite) {
  const Mesh body = voxel_mesh(box_cells({0, 0, 0}, {3, 3, 8}), 0.05, 0.0);
  const Mesh ball = voxel_mesh(box_cells({6, 0, 3}, {7, 1, 4}), 0.05, 0.0);  // floats aside
  const Mesh mesh = merge(body, ball);
  const int first_ball_vertex = body.num_vertices();
  // Bone 0 inside the body; bone 1 entirely outside, above the body.
  const Skeleton skeleton = chain({{0.07, 0.08, 0.1}, {0.075, 0.07, 0.3}, {0.08, 0.075, 0.6}});
  const Eigen::Vector3d j0(0.07, 0.08, 0.1), j1(0.075, 0.07, 0.3);
  for (const std::string unreached : {"restart", "euclidean"}) {
    SCOPED_TRACE(unreached);
    const Eigen::MatrixXd D = make("{unreached: " + unreached + "}").compute(mesh, skeleton);
    ASSERT_EQ(D.cols(), 3);
    EXPECT_TRUE(D.allFinite());
    EXPECT_TRUE((D.array() >= 0).all());
    for (int v = first_ball_vertex; v < mesh.num_vertices(); ++v) {
      // The body wall hides the ball from bone 0: penalty 8 on top of the straight line.
      const Eigen::Vector3d p = mesh.V.row(v).transpose();
      const double euclid = (p - closest_on_segment(p, j0, j1)).norm();
      if (unreached == "euclidean") {
        EXPECT_NEAR(D(v, 0), 8.0 + euclid, 1e-12);
      } else {
        EXPECT_GE(D(v, 0), 8.0 + euclid - 1e-12);
        EXPECT_LT(D(v, 0), 8.0 + euclid + 0.2);  // plus at most a walk around a 5 cm cube
      }
    }
  }
}

TEST(VolumetricGeodesic, OneJointSkeletonIsOneHelperBone) {
  const Mesh mesh = voxel_mesh(box_cells({0, 0, 0}, {3, 3, 3}), 0.05, 0.0);
  const Eigen::Vector3d joint(0.07, 0.08, 0.075);
  Eigen::MatrixXd positions(1, 3);
  positions.row(0) = joint.transpose();
  const Skeleton skeleton = Skeleton::from_parent_names({"root"}, positions, {""}, "one joint");
  const Eigen::MatrixXd D = make("{filter_far_visible: false}").compute(mesh, skeleton);
  ASSERT_EQ(D.rows(), mesh.num_vertices());
  ASSERT_EQ(D.cols(), 1);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    EXPECT_NEAR(D(v, 0), (mesh.V.row(v).transpose() - joint).norm(), 1e-12);
  }
}

TEST(VolumetricGeodesic, SameResultWithOneAndTwoThreads) {
  const Mesh mesh = voxel_mesh(u_cells(), 0.05, 0.02, 3);
  const Skeleton skeleton = chain({{0.05, 0.05, 0.4}, {0.05, 0.05, 0.05}, {0.3, 0.05, 0.05},
                                   {0.3, 0.05, 0.4}});
  const auto distance = make();
  Eigen::MatrixXd one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = distance.compute(mesh, skeleton);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = distance.compute(mesh, skeleton);
  }
  EXPECT_TRUE(one.allFinite());
  EXPECT_EQ(one, two);
}

TEST(VolumetricGeodesic, TimingsAreFilled) {
  const Mesh mesh = voxel_mesh(box_cells({0, 0, 0}, {3, 3, 6}), 0.05, 0.0);
  const Skeleton skeleton = chain({{0.07, 0.08, 0.05}, {0.075, 0.07, 0.25}});
  VolumetricGeodesicTimings timings{-1, -1, -1};
  make().compute(mesh, skeleton, &timings);
  EXPECT_GE(timings.aabb, 0);
  EXPECT_GE(timings.visibility, 0);
  EXPECT_GE(timings.dijkstra, 0);
}

// ---- registry, options and errors ---------------------------------------------------------------

TEST(VolumetricGeodesic, CreatedThroughTheRegistry) {
  const auto config = config::Config::parse(
      "distance: {type: volumetric_geodesic, samples_per_bone: 4, unreached: euclidean}");
  const auto distance = distance_registry().create(config.root()["distance"]);
  const auto* concrete = dynamic_cast<const VolumetricGeodesic*>(distance.get());
  ASSERT_NE(concrete, nullptr);
  EXPECT_EQ(concrete->options().samples_per_bone, 4);
  EXPECT_EQ(concrete->options().unreached, "euclidean");
  EXPECT_DOUBLE_EQ(concrete->options().unreached_penalty, 8.0);
}

TEST(VolumetricGeodesic, OptionErrorsNameTheKey) {
  expect_error<ConfigError>([] { make("{sample_per_bone: 4}"); },
                            {"test.yaml:1: sample_per_bone: ",
                             "unknown field of distance 'volumetric_geodesic'",
                             "did you mean 'samples_per_bone'?"});
  expect_error<ConfigError>([] { make("{samples_per_bone: 1}"); },
                            {"samples_per_bone: must be at least 2"});
  expect_error<ConfigError>([] { make("{samples_per_bone: many}"); },
                            {"samples_per_bone: expected an integer, got"});
  expect_error<ConfigError>([] { make("{ray_epsilon: 0}"); }, {"ray_epsilon: must be positive"});
  expect_error<ConfigError>([] { make("{filter_percentile: 101}"); },
                            {"filter_percentile: must be in [0, 100]"});
  expect_error<ConfigError>([] { make("{filter_factor: 0.5}"); },
                            {"filter_factor: must be at least 1"});
  expect_error<ConfigError>([] { make("{unreached: nearest}"); },
                            {"unreached: must be 'restart' or 'euclidean', got 'nearest'"});
  expect_error<ConfigError>([] { make("{unreached_penalty: -1}"); },
                            {"unreached_penalty: must be finite and non-negative"});
}

TEST(VolumetricGeodesic, InvalidMeshIsAGeometryError) {
  Mesh mesh = voxel_mesh(box_cells({0, 0, 0}, {2, 2, 2}), 0.05, 0.0);
  mesh.F(3, 1) = mesh.num_vertices() + 5;
  const Skeleton skeleton = chain({{0.05, 0.05, 0.02}, {0.05, 0.05, 0.08}});
  expect_error<geometry::GeometryError>([&] { make().compute(mesh, skeleton); },
                                        {"distance 'volumetric_geodesic'", "face 3"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::distances

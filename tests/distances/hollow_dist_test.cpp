// `hollow_dist` (HeterSkinNet Sec. 3.1, Algorithm 1, Eq. 1): the fast path against a naive
// reference written straight from the paper (full R×R×R cube, std::map/std::set cells, CGAL's
// exact triangle/segment–box tests over all cells, std::queue BFS, restarts found by scanning
// every cell), and shapes with known answers.

#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <queue>
#include <random>
#include <set>

#include "framework/core/registry.hpp"
#include "framework/distances/euclidean.hpp"
#include "framework/geometry/closest_point_on_segment.hpp"
#include "framework/distances/hollow_dist.hpp"
#include "framework/geometry/voxel_grid.hpp"
#include "tests/distances/shapes.hpp"
#include "tests/test_util.hpp"

namespace skinlab::distances {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using geometry::Mesh;
using geometry::point_segment_distance;
using geometry::Skeleton;
using skinlab::testing::expect_error;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

std::shared_ptr<Distance> make(const std::string& yaml) {
  return distance_registry().create(config::Config::parse(yaml, "test.yaml").root());
}

Eigen::MatrixXd hollow(const Mesh& mesh, const Skeleton& skeleton, int resolution) {
  return make("{type: hollow_dist, resolution: " + std::to_string(resolution) + "}")
      ->compute(mesh, skeleton);
}

// ---- naive reference ---------------------------------------------------------------------------

/// Cell key ordered as (z, y, x), the tie-break order of Algorithm 1 line 20 we chose.
using Key = std::array<int, 3>;

struct Reference {
  int R = 0;
  double sc = 0;
  Eigen::Vector3d origin;  // lower corner of the full cube
  std::set<Key> mesh;      // mesh cells
  struct Bone {
    std::map<Key, int> steps;  // absent = ∞
    std::map<Key, int> phase;
    Eigen::VectorXd D;  // #V
    int restarts = 0;
  };
  std::vector<Bone> bones;

  CGAL::Bbox_3 box(const Key& k) const {
    const Eigen::Vector3d lo = origin + sc * Eigen::Vector3d(k[2], k[1], k[0]);
    return {lo.x(), lo.y(), lo.z(), lo.x() + sc, lo.y() + sc, lo.z() + sc};
  }
  Eigen::Vector3d center(const Key& k) const {
    return origin + sc * Eigen::Vector3d(k[2] + 0.5, k[1] + 0.5, k[0] + 0.5);
  }
  bool inside(const Key& k) const {
    for (int a : k)
      if (a < 0 || a >= R) return false;
    return true;
  }
  Key cell_of(const Eigen::Vector3d& p) const {
    Key k;
    for (int a = 0; a < 3; ++a) {
      const int c = static_cast<int>(std::floor((p[a] - origin[a]) / sc));
      k[2 - a] = std::min(std::max(c, 0), R - 1);
    }
    return k;
  }
  std::vector<Key> neighbours(const Key& k) const {
    std::vector<Key> out;
    for (int a = 0; a < 3; ++a) {
      for (int d : {-1, 1}) {
        Key n = k;
        n[a] += d;
        if (inside(n)) out.push_back(n);
      }
    }
    return out;
  }
  std::vector<Key> all_cells() const {
    std::vector<Key> out;
    for (int z = 0; z < R; ++z)
      for (int y = 0; y < R; ++y)
        for (int x = 0; x < R; ++x) out.push_back({z, y, x});
    return out;
  }
};

Kernel::Point_3 point(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

Reference reference(const Mesh& mesh, const Skeleton& skeleton, int R, int margin) {
  Reference ref;
  ref.R = R;
  Eigen::Vector3d lo = mesh.V.colwise().minCoeff(), hi = mesh.V.colwise().maxCoeff();
  lo = lo.cwiseMin(skeleton.positions.colwise().minCoeff().transpose());
  hi = hi.cwiseMax(skeleton.positions.colwise().maxCoeff().transpose());
  ref.sc = (hi - lo).maxCoeff() / (R - 2 * margin - 1);
  ref.origin = (lo + hi) / 2 - Eigen::Vector3d::Constant(R * ref.sc / 2);

  // Voxelisation: every cell against every triangle (a cheap bounding-box reject first).
  for (const Key& k : ref.all_cells()) {
    const CGAL::Bbox_3 box = ref.box(k);
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const Kernel::Triangle_3 t(point(mesh.V.row(mesh.F(f, 0))), point(mesh.V.row(mesh.F(f, 1))),
                                 point(mesh.V.row(mesh.F(f, 2))));
      if (CGAL::do_overlap(t.bbox(), box) && CGAL::do_intersect(t, box)) {
        ref.mesh.insert(k);
        break;
      }
    }
  }
  for (int v = 0; v < mesh.num_vertices(); ++v) ref.mesh.insert(ref.cell_of(mesh.V.row(v)));

  const Eigen::MatrixXd segments = skeleton.bone_segments();
  for (Eigen::Index b = 0; b < segments.rows(); ++b) {
    const Eigen::Vector3d a = segments.row(b).head<3>(), e = segments.row(b).tail<3>();
    Reference::Bone bone;
    std::queue<Key> Q;
    for (const Key& k : ref.all_cells()) {  // lines 5–9
      const bool hit = a == e
                           ? CGAL::do_intersect(point(a), ref.box(k))
                           : CGAL::do_intersect(Kernel::Segment_3(point(a), point(e)), ref.box(k));
      if (hit) {
        bone.steps[k] = 0;
        bone.phase[k] = 0;
        Q.push(k);
      }
    }
    auto untraversed_mesh_cell_exists = [&] {
      for (const Key& k : ref.mesh)
        if (!bone.steps.count(k)) return true;
      return false;
    };
    int phase = 0;
    while (untraversed_mesh_cell_exists()) {  // line 10
      while (!Q.empty()) {                    // lines 11–19
        const Key c = Q.front();
        Q.pop();
        for (const Key& n : ref.neighbours(c)) {
          if (bone.steps.count(n)) continue;
          if (ref.mesh.count(c) && !ref.mesh.count(n)) continue;
          bone.steps[n] = bone.steps[c] + 1;
          bone.phase[n] = phase;
          Q.push(n);
        }
      }
      // Lines 20–24, literally: also after the last mesh cell was reached (harmless: it only
      // labels hollow cells of a later phase, which Eq. 1 never reads).
      Key nearest{-1, -1, -1};
      int best = std::numeric_limits<int>::max();
      for (const Key& k : ref.all_cells()) {  // (z, y, x) order: the first minimum wins ties
        if (!ref.mesh.count(k) || !bone.steps.count(k) || bone.steps[k] >= best) continue;
        for (const Key& n : ref.neighbours(k)) {
          if (!ref.mesh.count(n) && !bone.steps.count(n)) {
            nearest = k;
            best = bone.steps[k];
            break;
          }
        }
      }
      if (nearest[0] < 0) break;
      ++phase;
      if (untraversed_mesh_cell_exists()) ++bone.restarts;
      for (const Key& n : ref.neighbours(nearest)) {
        if (!ref.mesh.count(n) && !bone.steps.count(n)) {
          bone.steps[n] = best + 1;
          bone.phase[n] = phase;
          Q.push(n);
        }
      }
    }
    // Eq. 1.
    bone.D.resize(mesh.num_vertices());
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      const Eigen::Vector3d p = mesh.V.row(v);
      const Key c = ref.cell_of(p);
      const int s = bone.steps.at(c);
      if (s == 0) {
        bone.D[v] = point_segment_distance(p, a, e);
        continue;
      }
      double d = std::numeric_limits<double>::infinity();
      for (const Key& n : ref.neighbours(c)) {
        auto it = bone.steps.find(n);
        if (it == bone.steps.end() || it->second != s - 1 || bone.phase.at(n) > bone.phase.at(c))
          continue;
        d = std::min(d, (s - 1) * ref.sc + (ref.center(n) - p).norm());
      }
      bone.D[v] = d;
    }
    ref.bones.push_back(std::move(bone));
  }
  return ref;
}

/// Compares voxelisation, every mesh cell's distance and D of the fast path with the reference.
void expect_matches_reference(const Mesh& mesh, const Skeleton& skeleton, int R, int margin) {
  const Reference ref = reference(mesh, skeleton, R, margin);
  HollowDist::Options options;
  options.resolution = R;
  options.margin_cells = margin;
  const HollowDist hd(options);
  const geometry::SurfaceVoxels voxels = hd.voxelize(mesh, skeleton);
  const auto& grid = voxels.grid();
  ASSERT_NEAR(grid.cell_size(), ref.sc, 1e-12);
  const auto& off = grid.cube_offset();
  auto fast_index = [&](const Key& k) {
    return grid.index(k[2] - off[0], k[1] - off[1], k[0] - off[2]);
  };

  // Same mesh cells: every reference mesh cell lies in the stored slab, and vice versa.
  int fast_mesh = 0;
  for (const Key& k : ref.mesh) {
    ASSERT_TRUE(grid.stored(fast_index(k))) << "mesh cell outside the slab";
    EXPECT_TRUE(voxels.is_mesh(fast_index(k)))
        << "cell z=" << k[0] << " y=" << k[1] << " x=" << k[2];
  }
  for (int i = 0; i < grid.num_padded(); ++i) fast_mesh += voxels.is_mesh(i);
  EXPECT_EQ(fast_mesh, static_cast<int>(ref.mesh.size()));
  EXPECT_EQ(voxels.num_mesh_cells(), fast_mesh);

  const Eigen::MatrixXd segments = skeleton.bone_segments();
  const Eigen::MatrixXd D = hd.compute(mesh, skeleton);
  HollowBfs bfs(voxels);
  int total_restarts = 0;
  for (Eigen::Index b = 0; b < segments.rows(); ++b) {
    bfs.run(segments.row(b).head<3>(), segments.row(b).tail<3>());
    const auto& rb = ref.bones[b];
    EXPECT_EQ(bfs.restarts(), rb.restarts) << "bone " << b;
    total_restarts += rb.restarts;
    for (const Key& k : ref.mesh) {
      ASSERT_EQ(bfs.steps(fast_index(k)), rb.steps.at(k))
          << "bone " << b << " cell z=" << k[0] << " y=" << k[1] << " x=" << k[2];
    }
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      EXPECT_NEAR(D(v, b), rb.D[v], 1e-9) << "bone " << b << " vertex " << v;
    }
  }
  // The shapes below are chosen so the restart path is exercised.
  EXPECT_GT(total_restarts, 0);
}

// A torus with a bone inside its tube, a detached sphere (reached only by restarts), a bone
// outside everything, and leaf helper bones, rotated off the grid axes.
void torus_and_sphere(Mesh& mesh, Skeleton& skeleton) {
  mesh = testing::MeshBuilder()
             .torus({0, 0, 0}, 0.6, 0.2, 20, 10)
             .sphere({1.3, 0, 0}, 0.15, 10, 6)
             .build();
  Eigen::MatrixXd joints(4, 3);
  joints << 0.6, 0.0, 0.02,  // in the tube
      0.55, 0.22, 0.0,       // in the tube
      0.0, -0.75, 0.45,      // outside, above
      -0.9, 0.0, -0.1;       // outside
  skeleton = Skeleton::from_parent_names({"a", "b", "c", "d"}, joints, {"", "a", "a", "c"},
                                         "torus skeleton");
  testing::rotate(mesh, skeleton, testing::some_rotation(0.3, 0.2, 0.1));
}

TEST(HollowDist, MatchesNaiveReferenceTorusAndDetachedSphere) {
  Mesh mesh;
  Skeleton skeleton;
  torus_and_sphere(mesh, skeleton);
  expect_matches_reference(mesh, skeleton, 28, 2);
}

TEST(HollowDist, MatchesNaiveReferenceTightMarginAndBoxes) {
  // Margin of one cell; two boxes and a bone crossing the surface of the first one.
  Mesh mesh = testing::MeshBuilder()
                  .box({0, 0, 0}, {0.6, 0.3, 0.25}, 3)
                  .box({0.8, 0.05, 0.0}, {1.0, 0.25, 0.2}, 2)
                  .build();
  Eigen::MatrixXd joints(3, 3);
  joints << 0.1, 0.15, 0.12, 0.45, 0.16, 0.13, 0.7, 0.15, 0.1;
  Skeleton skeleton = testing::chain(joints);
  testing::rotate(mesh, skeleton, testing::some_rotation(0.5, -0.3, 0.7));
  expect_matches_reference(mesh, skeleton, 18, 1);
}

// ---- shapes with known answers -----------------------------------------------------------------

// A closed U-shaped prism: arms x∈[0,w] and x∈[2w,3w] from y=0 to y=L, joined by the base
// y∈[0,w]; depth w along z.
constexpr double kW = 0.25, kL = 1.0;

Mesh u_tube() {
  const std::vector<Eigen::Vector2d> outline = {
      {0, 0}, {3 * kW, 0}, {3 * kW, kL}, {2 * kW, kL}, {2 * kW, kW}, {kW, kW}, {kW, kL}, {0, kL}};
  const std::vector<Eigen::Vector4d> caps = {
      {0, 0, kW, kL}, {kW, 0, 2 * kW, kW}, {2 * kW, 0, 3 * kW, kL}};
  return testing::MeshBuilder().prism(outline, caps, kW, 0.05).build();
}

TEST(HollowDist, UTubeFollowsTheTubeEuclideanDoesNot) {
  const Mesh mesh = u_tube();
  Eigen::MatrixXd joints(2, 3);
  joints << kW / 2, 0.9, kW / 2,  // bone inside the left arm, pointing down
      kW / 2, 0.6, kW / 2;
  const Skeleton skeleton = testing::chain(joints);
  const int R = 40;
  const Eigen::MatrixXd H = hollow(mesh, skeleton, R);
  const Eigen::MatrixXd E = make("{type: euclidean}")->compute(mesh, skeleton);
  const double sc = 1.0 / (R - 2 * 2 - 1);  // longest side 1 (y)
  const double tolerance = 4 * sc;

  // Vertex at the top of the right arm's inner wall, mid-depth: across the gap from the bone.
  const Eigen::Vector3d far(2 * kW, kL, kW / 2);
  const int v = testing::nearest_vertex(mesh, far);
  ASSERT_LT((mesh.V.row(v).transpose() - far).norm(), 1e-12);
  // Shortest path inside the U (a lower bound for any path that does not cross the surface):
  // from the bone's lower end around the inner corners (w, w) and (2w, w), then up the arm.
  const double inside =
      (Eigen::Vector2d(kW / 2, 0.6) - Eigen::Vector2d(kW, kW)).norm() + kW + (kL - kW);
  // The 6-connected search measures that path in the L1 metric: down, across, up.
  const double manhattan = (0.6 - kW) + (2 * kW - kW / 2) + (kL - kW);
  EXPECT_GE(H(v, 0), inside - tolerance);
  EXPECT_LE(H(v, 0), manhattan + tolerance);
  EXPECT_LT(E(v, 0), inside - tolerance);  // the straight line crosses the gap
  EXPECT_NEAR(E(v, 0), (Eigen::Vector2d(2 * kW, kL) - Eigen::Vector2d(kW / 2, 0.9)).norm(), 1e-12);

  // A vertex on the bone's own arm, level with it: Hollow and Euclidean agree within cells.
  const int near = testing::nearest_vertex(mesh, {0, 0.75, kW / 2});
  EXPECT_NEAR(H(near, 0), E(near, 0), 3 * sc);
  // The helper bone at the lower joint behaves the same way.
  EXPECT_GE(H(v, 1), inside - tolerance);
}

TEST(HollowDist, DetachedPartIsReachedByRestart) {
  const Mesh mesh = testing::MeshBuilder()
                        .box({0, 0, 0}, {1, 0.3, 0.3}, 4)
                        .box({1.3, 0, 0}, {1.6, 0.3, 0.3}, 3)
                        .build();
  Eigen::MatrixXd joints(2, 3);
  joints << 0.1, 0.15, 0.15, 0.9, 0.15, 0.15;  // inside the first box
  const Skeleton skeleton = testing::chain(joints);
  const HollowDist hd(HollowDist::Options{32, 2});
  const auto voxels = hd.voxelize(mesh, skeleton);
  HollowBfs bfs(voxels);
  bfs.run(joints.row(0).transpose(), joints.row(1).transpose());
  EXPECT_GE(bfs.restarts(), 1);  // the outside, and with it the second box, needs a restart

  const Eigen::MatrixXd H = hd.compute(mesh, skeleton);
  const Eigen::MatrixXd E = Euclidean().compute(mesh, skeleton);
  const double sc = voxels.grid().cell_size();
  ASSERT_TRUE(H.allFinite());
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    for (int b = 0; b < 2; ++b) {
      EXPECT_GE(H(v, b), E(v, b) - 2 * sc) << "vertex " << v << " bone " << b;
    }
  }
  // The second box's far face is beyond the end of the first box: the path must leave the first
  // box (restart next to the bone: the side walls are 0.15 away) and go around.
  const int v = testing::nearest_vertex(mesh, {1.6, 0.15, 0.15});
  EXPECT_GT(H(v, 0), E(v, 0) + 0.1);
}

TEST(HollowDist, BoneOutsideTheMeshGoesAround) {
  const Mesh mesh = testing::MeshBuilder().box({0, 0, 0}, {1, 1, 1}, 6).build();
  Eigen::MatrixXd joints(2, 3);
  joints << 1.4, 0.5, 0.5, 1.6, 0.5, 0.5;
  const Skeleton skeleton = testing::chain(joints);
  const int R = 32;
  const Eigen::MatrixXd H = hollow(mesh, skeleton, R);
  const Eigen::MatrixXd E = Euclidean().compute(mesh, skeleton);
  const double sc = 1.6 / (R - 2 * 2 - 1);
  ASSERT_TRUE(H.allFinite());
  // Centre of the far face x = 0: around the box over an edge, never through it.
  const int far = testing::nearest_vertex(mesh, {0, 0.5, 0.5});
  const double around = std::hypot(0.4, 0.5) + 1.0 + 0.5;
  EXPECT_GE(H(far, 0), around - 4 * sc);
  EXPECT_NEAR(E(far, 0), 1.4, 1e-12);
  // Centre of the near face: straight across the gap.
  const int near = testing::nearest_vertex(mesh, {1, 0.5, 0.5});
  EXPECT_NEAR(H(near, 0), 0.4, 2 * sc);
}

TEST(HollowDist, OneJointSkeletonIsOneHelperBone) {
  const Mesh mesh = testing::MeshBuilder().box({0, 0, 0}, {1, 0.8, 0.6}, 4).build();
  Eigen::MatrixXd joint(1, 3);
  joint << 0.4, 0.35, 0.3;
  const Skeleton skeleton = testing::chain(joint);
  const int R = 24;
  const Eigen::MatrixXd H = hollow(mesh, skeleton, R);
  ASSERT_EQ(H.cols(), 1);
  ASSERT_EQ(H.rows(), mesh.num_vertices());
  const double sc = 1.0 / (R - 2 * 2 - 1);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    // Inside a convex box the search is a 6-connected BFS: between the Euclidean and the L1
    // distance (≤ √3·Euclidean), up to the cell size.
    const double e = (mesh.V.row(v) - joint.row(0)).norm();
    EXPECT_GE(H(v, 0), e - 2 * sc) << "vertex " << v;
    EXPECT_LE(H(v, 0), std::sqrt(3.0) * (e + 2 * sc)) << "vertex " << v;
  }
}

TEST(HollowDist, VertexInBoneCellUsesEuclideanDistance) {
  const Mesh mesh = testing::MeshBuilder().box({0, 0, 0}, {1, 0.5, 0.5}, 4).build();
  Eigen::MatrixXd joints(2, 3);
  joints << 0.0, 0.25, 0.25, 1.0, 0.25, 0.25;  // ends on the two end faces
  const Skeleton skeleton = testing::chain(joints);
  const HollowDist hd(HollowDist::Options{16, 2});
  const auto voxels = hd.voxelize(mesh, skeleton);
  HollowBfs bfs(voxels);
  bfs.run(joints.row(0).transpose(), joints.row(1).transpose());
  const Eigen::MatrixXd H = hd.compute(mesh, skeleton);
  int in_bone_cells = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    if (bfs.steps(voxels.vertex_cells()[v]) != 0) continue;
    ++in_bone_cells;
    EXPECT_DOUBLE_EQ(H(v, 0),
                     point_segment_distance(mesh.V.row(v).transpose(), joints.row(0).transpose(),
                                            joints.row(1).transpose()));
  }
  EXPECT_GT(in_bone_cells, 0);  // the end-face centres
}

TEST(HollowDist, UnreachedVertexIsAGeometryErrorNamingVertexAndBone) {
  const Mesh mesh = testing::MeshBuilder().box({0, 0, 0}, {1, 1, 1}, 1).build();
  Eigen::MatrixXd joints(2, 3);
  joints << 0.5, 0.5, 0.2, 0.5, 0.5, 0.8;
  const Skeleton skeleton =
      Skeleton::from_parent_names({"hips", "spine"}, joints, {"", "hips"}, "test");
  const auto voxels = HollowDist(HollowDist::Options{}).voxelize(mesh, skeleton);
  HollowBfs bfs(voxels);  // no run: nothing is reached
  Eigen::VectorXd out(mesh.num_vertices());
  expect_error<geometry::GeometryError>(
      [&] {
        bfs.vertex_distances(mesh, joints.row(0).transpose(), joints.row(1).transpose(), out,
                             describe_bone(skeleton, 0));
      },
      {"hollow_dist", "vertex 0", "bone 0 ('hips' -> 'spine')", "no finite distance"});
  EXPECT_EQ(describe_bone(skeleton, 1), "helper bone 1 (at 'spine')");
}

TEST(HollowDist, InvalidMeshIsAGeometryError) {
  Mesh mesh = testing::MeshBuilder().box({0, 0, 0}, {1, 1, 1}, 1).build();
  mesh.V(3, 1) = std::nan("");
  Eigen::MatrixXd joint = Eigen::MatrixXd::Constant(1, 3, 0.5);
  expect_error<geometry::GeometryError>([&] { hollow(mesh, testing::chain(joint), 16); },
                                        {"hollow_dist", "vertex 3", "non-finite"});
}

TEST(HollowDist, ThreadCountDoesNotChangeTheResult) {
  Mesh mesh;
  Skeleton skeleton;
  torus_and_sphere(mesh, skeleton);
  const Eigen::MatrixXd parallel = hollow(mesh, skeleton, 40);
  const HollowDist hd(HollowDist::Options{40, 2});
  const auto voxels = hd.voxelize(mesh, skeleton);
  HollowBfs bfs(voxels);
  const Eigen::MatrixXd segments = skeleton.bone_segments();
  for (Eigen::Index b = 0; b < segments.rows(); ++b) {  // one worker, bones in order
    Eigen::VectorXd column(mesh.num_vertices());
    bfs.run(segments.row(b).head<3>(), segments.row(b).tail<3>());
    bfs.vertex_distances(mesh, segments.row(b).head<3>(), segments.row(b).tail<3>(), column, "");
    EXPECT_EQ(column, parallel.col(b)) << "bone " << b;
  }
}

// ---- grid and voxeliser ------------------------------------------------------------------------

TEST(HollowDistGrid, FitsTheCubeSlabWithMargins) {
  const Mesh mesh = testing::MeshBuilder().box({-1, 2, 0}, {1, 2.5, 0.3}, 1).build();
  Eigen::MatrixXd joint(1, 3);
  joint << 0, 2.2, 0.7;  // the skeleton widens the box along z
  const Skeleton skeleton = testing::chain(joint);
  const auto grid = geometry::VoxelGrid::fit(mesh, skeleton, 88, 2);
  EXPECT_DOUBLE_EQ(grid.cell_size(), 2.0 / (88 - 5));
  EXPECT_EQ(grid.dims()[0], 88);
  const Eigen::Vector3d lo(-1, 2, 0), hi(1, 2.5, 0.7);
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(grid.dims()[a], 88);
    EXPECT_EQ((88 - grid.dims()[a]) % 2, 0);
    EXPECT_EQ(grid.cube_offset()[a], (88 - grid.dims()[a]) / 2);
    // At least margin + 1/2 empty cells on both sides.
    EXPECT_GE(lo[a] - grid.origin()[a], 2.5 * grid.cell_size() - 1e-9) << "axis " << a;
    EXPECT_GE(grid.origin()[a] + grid.dims()[a] * grid.cell_size() - hi[a],
              2.5 * grid.cell_size() - 1e-9)
        << "axis " << a;
  }
  EXPECT_LT(grid.dims()[1], 40);  // the slab is much thinner than the cube
  // Padding and index round trip.
  const int idx = grid.index(3, 4, 5);
  EXPECT_EQ(grid.coords(idx), (std::array<int, 3>{3, 4, 5}));
  EXPECT_TRUE(grid.stored(idx));
  EXPECT_FALSE(grid.stored(grid.index(-1, 0, 0)));
  EXPECT_EQ(grid.cell_of(grid.center(idx)), idx);
}

TEST(HollowDistGrid, TriangleBoxOverlapMatchesCgal) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1.6, 1.6);
  const Eigen::Vector3d center(0.1, -0.2, 0.05), half(0.5, 0.5, 0.5);
  const CGAL::Bbox_3 box(-0.4, -0.7, -0.45, 0.6, 0.3, 0.55);
  int hits = 0, misses = 0;
  for (int t = 0; t < 20000; ++t) {
    const Eigen::Vector3d a(U(rng), U(rng), U(rng)), b(U(rng), U(rng), U(rng));
    Eigen::Vector3d c(U(rng), U(rng), U(rng));
    if (t % 4 == 0) {  // segment (a degenerate triangle)
      const bool expected = CGAL::do_intersect(Kernel::Segment_3(point(a), point(b)), box);
      EXPECT_EQ(geometry::triangle_box_overlap(a, b, b, center, half), expected) << "segment " << t;
      continue;
    }
    if (t % 4 == 1) c = a + 0.63 * (b - a);  // collinear: the triangle is the segment [a, b]
    const bool expected =
        t % 4 == 1 ? CGAL::do_intersect(Kernel::Segment_3(point(a), point(b)), box)
                   : CGAL::do_intersect(Kernel::Triangle_3(point(a), point(b), point(c)), box);
    const bool actual = geometry::triangle_box_overlap(a, b, c, center, half);
    EXPECT_EQ(actual, expected) << "triangle " << t;
    (actual ? hits : misses)++;
  }
  EXPECT_GT(hits, 1000);
  EXPECT_GT(misses, 1000);
  // A point: inside, on a face (closed box), outside.
  EXPECT_TRUE(geometry::triangle_box_overlap(center, center, center, center, half));
  const Eigen::Vector3d on_face = center + Eigen::Vector3d(0.5, 0.1, -0.2);
  EXPECT_TRUE(geometry::triangle_box_overlap(on_face, on_face, on_face, center, half));
  const Eigen::Vector3d out = center + Eigen::Vector3d(0.51, 0, 0);
  EXPECT_FALSE(geometry::triangle_box_overlap(out, out, out, center, half));
}

TEST(HollowDistGrid, ThinSheetIsNotMissed) {
  // A single triangle thinner than a cell and not through any cell centre is still voxelised.
  Mesh mesh;
  mesh.V.resize(3, 3);
  mesh.V << 0.013, 0.011, 0.0101, 0.97, 0.012, 0.0102, 0.5, 0.9, 0.0103;
  mesh.F.resize(1, 3);
  mesh.F << 0, 1, 2;
  Eigen::MatrixXd joint(1, 3);
  joint << 0.5, 0.5, 0.0;
  const auto voxels = geometry::SurfaceVoxels::voxelize(
      mesh, geometry::VoxelGrid::fit(mesh, testing::chain(joint), 16, 2));
  // The sheet passes ~0.04 (half a cell) from every cell centre, so sampling cell centres would
  // miss it entirely; the overlap test marks every cell it passes through (about 11×11 / 2).
  EXPECT_GE(voxels.num_mesh_cells(), 60);
  const auto& grid = voxels.grid();
  for (int i = 0; i < grid.num_padded(); ++i) {
    if (!voxels.is_mesh(i)) continue;
    const Eigen::Vector3d c = grid.center(i);
    EXPECT_LE(std::abs(c.z() - 0.0102), grid.cell_size()) << "a cell away from the sheet";
  }
}

// ---- options -----------------------------------------------------------------------------------

TEST(HollowDistOptions, DefaultsFollowThePaper) {
  const auto o = HollowDist::Options::from(config::Config::parse("{type: hollow_dist}").root());
  EXPECT_EQ(o.resolution, 88);
  EXPECT_EQ(o.margin_cells, 2);
  const auto p = HollowDist::Options::from(
      config::Config::parse("{type: hollow_dist, resolution: 40, margin_cells: 3}").root());
  EXPECT_EQ(p.resolution, 40);
  EXPECT_EQ(p.margin_cells, 3);
}

TEST(HollowDistOptions, ErrorsNameTheField) {
  expect_error<ConfigError>(
      [] { make("{type: hollow_dist, resolutoin: 64}"); },
      {"test.yaml:1", "resolutoin", "unknown field of distance 'hollow_dist'",
       "did you mean 'resolution'?", "known fields: margin_cells, resolution, type"});
  expect_error<ConfigError>([] { make("{type: hollow_dist, resolution: 7}"); },
                            {"test.yaml:1", "resolution", "must be at least 8"});
  expect_error<ConfigError>([] { make("{type: hollow_dist, resolution: 2000}"); },
                            {"resolution", "must be at most 1024"});
  expect_error<ConfigError>([] { make("{type: hollow_dist, margin_cells: 0}"); },
                            {"margin_cells", "must be at least 1"});
  expect_error<ConfigError>([] { make("{type: hollow_dist, resolution: 8, margin_cells: 4}"); },
                            {"margin_cells", "must leave cells for the character"});
  expect_error<ConfigError>([] { make("{type: hollow_dist, resolution: fine}"); },
                            {"resolution", "expected"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::distances

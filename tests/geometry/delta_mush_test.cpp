// Delta Mush (Mancewicz et al. 2014): the rest pose stays put (a tube and a real game
// character), a rigid motion stays rigid (the real character's rigid parts too), a region whose neighbourhood moves rigidly under LBS
// keeps its LBS position, the kink of a hard-weighted bend is spread out, and bad input is an
// error naming the vertex.
#include "framework/geometry/delta_mush.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <random>

#include "framework/geometry/lbs.hpp"
#include "framework/geometry/load_character.hpp"
#include "framework/geometry/normalize.hpp"
#include "tests/shapes/tube.hpp"
#include "tests/test_util.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;

constexpr int kSides = 16, kRings = 41;  // a ring every 2.5 cm from y = 0 to y = 1

Mesh tube() {
  return skinlab::testing::TubeBuilder().tube({0, 0, 0}, {0, 1, 0}, 0.06, kSides, kRings).build();
}
int ring_of(int vertex) { return vertex < kSides * kRings ? vertex / kSides : -1; }  // −1: a cap centre

/// Joints at y = 0 (root) and y = 0.5 (the elbow).
Skeleton elbow() {
  Skeleton s;
  s.names = {"upper", "lower"};
  s.parents = {-1, 0};
  s.positions = (Eigen::MatrixXd(2, 3) << 0, 0, 0, 0, 0.5, 0).finished();
  return s;
}

/// Weight of the lower joint: 0 below y = 0.5 − band, 1 above 0.5 + band, linear between
/// (band 0: a hard switch at the elbow).
SparseWeights elbow_weights(const Mesh& mesh, double band) {
  SparseWeights W(mesh.num_vertices(), 2);
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    const double y = mesh.V(i, 1);
    const double w = band == 0 ? (y > 0.5 ? 1.0 : 0.0)
                               : std::clamp((y - (0.5 - band)) / (2 * band), 0.0, 1.0);
    if (w < 1) W.insert(i, 0) = 1 - w;
    if (w > 0) W.insert(i, 1) = w;
  }
  W.makeCompressed();
  return W;
}

Eigen::MatrixXd bend(const Mesh& mesh, const SparseWeights& W, double degrees) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return lbs(mesh.V, W, forward_kinematics(elbow(), {Eigen::Matrix3d::Identity(), R}));
}

/// Largest |length / rest length − 1| over the mesh's edges.
double max_edge_strain(const Mesh& mesh, const Eigen::MatrixXd& X) {
  double worst = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      const double rest = (mesh.V.row(a) - mesh.V.row(b)).norm();
      worst = std::max(worst, std::abs((X.row(a) - X.row(b)).norm() / rest - 1));
    }
  }
  return worst;
}

TEST(DeltaMush, TheRestPoseStaysPut) {
  const Mesh mesh = tube();
  const DeltaMush mush(mesh);
  int passthrough = -1;
  EXPECT_TRUE(mush.deform(mesh.V, &passthrough).isApprox(mesh.V, 1e-12));
  EXPECT_EQ(passthrough, 0);
  EXPECT_EQ(mush.passthrough(), 0);
  EXPECT_EQ(mush.num_vertices(), mesh.num_vertices());
}

TEST(DeltaMush, TheRestPoseOfARealCharacterStaysPut) {
  // Minetest's player (minetest-data, CC BY-SA 3.0): disjoint parts (head, limbs, hat layer)
  // and seams, as game meshes come.
  const std::filesystem::path player =
      "/usr/share/games/minetest/games/minetest_game/mods/player_api/models/character.b3d";
  ASSERT_TRUE(std::filesystem::exists(player)) << player << " is missing; run scripts/setup";
  Character c = load_character(player);
  normalize(c);
  const DeltaMush mush(c.mesh, {}, c.name);
  EXPECT_LT((mush.deform(c.mesh.V) - c.mesh.V).cwiseAbs().maxCoeff(), 1e-12);

  // The player is built of disjoint boxes (head, body, limbs), each following one bone, so every
  // connected part moves rigidly under LBS and Delta Mush leaves the LBS mesh as it is.
  std::mt19937 rng(5);
  const Eigen::MatrixXd posed = lbs(
      c.mesh.V, c.weights, forward_kinematics(c.skeleton, random_pose(c.skeleton, rng, 0.5, 30)));
  const Eigen::MatrixXd out = mush.deform(posed);
  EXPECT_GT((posed - c.mesh.V).rowwise().norm().maxCoeff(), 0.05);  // really posed
  EXPECT_LT((out - posed).rowwise().norm().maxCoeff(), 1e-10);
}

TEST(DeltaMush, ARigidMotionStaysRigid) {
  const Mesh mesh = tube();
  const DeltaMush mush(mesh, {20, 0.7});
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, -1).normalized()).toRotationMatrix();
  const Eigen::RowVector3d t(0.3, -1.2, 2.0);
  const Eigen::MatrixXd moved = (mesh.V * R.transpose()).rowwise() + t;
  EXPECT_LT((mush.deform(moved) - moved).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(DeltaMush, ARegionWhoseNeighbourhoodMovesRigidlyMovesAsLbs) {
  // A 5 cm blend band at the elbow (rings 18–22 change weight); with 10 iterations a vertex's
  // result depends on its 11-ring, so rings ≤ 6 and ≥ 34 (and the caps) move as LBS does.
  const Mesh mesh = tube();
  const DeltaMush mush(mesh, {10, 0.5});
  const Eigen::MatrixXd posed = bend(mesh, elbow_weights(mesh, 0.05), 70);
  const Eigen::MatrixXd out = mush.deform(posed);
  double far = 0, near = 0;
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    const int ring = ring_of(i);
    const double difference = (out.row(i) - posed.row(i)).norm();
    if (ring < 0 || ring <= 6 || ring >= 34) {
      far = std::max(far, difference);
    } else if (ring >= 18 && ring <= 22) {
      near = std::max(near, difference);
    }
  }
  EXPECT_LT(far, 1e-12);
  EXPECT_GT(near, 1e-3);  // at the elbow Delta Mush corrects LBS by millimetres
}

TEST(DeltaMush, SpreadsTheKinkOfAHardWeightedBend) {
  // Every vertex on one joint: LBS folds the tube at the elbow ring, crushing the inner edges
  // and stretching the outer ones; Delta Mush spreads the bend over its 10 rings.
  const Mesh mesh = tube();
  const DeltaMush mush(mesh, {10, 0.5});
  const Eigen::MatrixXd posed = bend(mesh, elbow_weights(mesh, 0), 60);
  const double lbs_strain = max_edge_strain(mesh, posed), mush_strain =
      max_edge_strain(mesh, mush.deform(posed));
  EXPECT_GT(lbs_strain, 0.5);
  EXPECT_LT(mush_strain, 0.5 * lbs_strain) << "LBS " << lbs_strain << ", delta mush " << mush_strain;
}

TEST(DeltaMush, AVertexOnNoFaceKeepsItsPosedPosition) {
  Mesh mesh = tube();
  mesh.V.conservativeResize(mesh.num_vertices() + 1, 3);
  mesh.V.row(mesh.num_vertices() - 1) << 1, 1, 1;
  const DeltaMush mush(mesh);
  EXPECT_EQ(mush.passthrough(), 1);
  Eigen::MatrixXd posed = mesh.V;
  posed.row(posed.rows() - 1) << 2, 3, 4;
  int passthrough = 0;
  const Eigen::MatrixXd out = mush.deform(posed, &passthrough);
  EXPECT_EQ(passthrough, 1);
  EXPECT_EQ(out.row(out.rows() - 1), posed.row(posed.rows() - 1));
}

TEST(DeltaMush, BadInputIsAnErrorNamingTheSourceAndVertex) {
  const Mesh mesh = tube();
  expect_error<GeometryError>([&] { DeltaMush(mesh, {0, 0.5}, "tube.obj"); },
                              {"tube.obj", "iterations >= 1", "0"});
  expect_error<GeometryError>([&] { DeltaMush(mesh, {10, 1.5}, "tube.obj"); },
                              {"tube.obj", "step", "(0, 1]"});
  const DeltaMush mush(mesh, {}, "tube.obj");
  expect_error<GeometryError>([&] { mush.deform(mesh.V.topRows(5)); },
                              {"tube.obj", "5x3", std::to_string(mesh.num_vertices())});
  Eigen::MatrixXd posed = mesh.V;
  posed(17, 2) = std::nan("");
  expect_error<GeometryError>([&] { mush.deform(posed); }, {"tube.obj", "vertex 17", "non-finite"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

// ACAP features (mesh-sequence BiLSTM Sec. 3.1, Eq. 1; Gao et al. 2019): the polar
// decomposition and rotation-vector representatives, exact recovery of rigid motions and
// uniform scalings, the round trip features → mesh on bent and twisted tubes, rotation angles
// past π that stay continuous over a sequence and over the mesh, connected parts placed where
// asked, the [−0.95, 0.95] scaling, and errors that name the vertex.
#include "framework/geometry/acap.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "tests/shapes/tube.hpp"
#include "tests/test_util.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;

constexpr int kSides = 12, kRings = 21;  // along z from 0 to 1, radius 0.1

Mesh tube() {
  return skinlab::testing::TubeBuilder().tube({0, 0, 0}, {0, 0, 1}, 0.1, kSides, kRings).build();
}

/// Every vertex turned about the z axis by `angle` · clamp((z − z0) / (z1 − z0), 0, 1): a twist
/// over [z0, z1], rigid above it (z0 = 0, z1 = 1: growing along the whole tube).
Eigen::MatrixXd twisted(const Mesh& m, double angle, double z0 = 0, double z1 = 1) {
  Eigen::MatrixXd V = m.V;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const double a = angle * std::clamp((m.V(i, 2) - z0) / (z1 - z0), 0.0, 1.0);
    V.row(i) = (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) * m.V.row(i).transpose()).transpose();
  }
  return V;
}

/// Bent into a quarter circle in the xz plane (the axis keeps its length, sections turn with it).
Eigen::MatrixXd bent(const Mesh& m) {
  const double radius = 2 / M_PI;  // the unit-length axis becomes a quarter circle
  Eigen::MatrixXd V = m.V;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const double phi = m.V(i, 2) / radius, r = radius - m.V(i, 0);
    V(i, 0) = radius - r * std::cos(phi);
    V(i, 2) = r * std::sin(phi);
  }
  return V;
}

double max_distance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).rowwise().norm().maxCoeff();
}

TEST(PolarDecompose, RotationTimesSymmetricWithReflectionsKeptInS) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Matrix3d T;
    for (int k = 0; k < 9; ++k) T(k / 3, k % 3) = g(rng);
    Eigen::Matrix3d R, S;
    polar_decompose(T, R, S);
    EXPECT_LT((R * S - T).norm(), 1e-12);
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    EXPECT_LT((S - S.transpose()).norm(), 1e-12);
    // A reflection is a negative eigenvalue of S, never in R.
    EXPECT_EQ(S.determinant() < 0, T.determinant() < 0);
  }
}

TEST(RotationVector, NearestRepresentativeOfTheSameRotation) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d r = 0.5 * M_PI * z;
  EXPECT_LT((nearest_rotation_vector(r, Eigen::Vector3d::Zero()) - r).norm(), 1e-15);
  EXPECT_LT((nearest_rotation_vector(r, 2.4 * M_PI * z) - 2.5 * M_PI * z).norm(), 1e-12);
  EXPECT_LT((nearest_rotation_vector(r, -1.2 * M_PI * z) - -1.5 * M_PI * z).norm(), 1e-12);
  // Every representative is the same rotation.
  for (double k : {-2.0, -1.0, 1.0, 3.0}) {
    const Eigen::Vector3d q = nearest_rotation_vector(r, (0.5 + 2 * k) * M_PI * z);
    EXPECT_LT((rotation_of(q) - rotation_of(r)).norm(), 1e-12) << k;
  }
  EXPECT_EQ(nearest_rotation_vector(Eigen::Vector3d::Zero(), z), Eigen::Vector3d::Zero());
  EXPECT_EQ(rotation_of(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity());
}

TEST(Acap, RigidMotionsAndUniformScalingsAreRecoveredExactly) {
  const Mesh m = tube();
  const AcapEncoder acap(m, "tube");
  EXPECT_EQ(acap.num_parts(), 1);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (double scale : {1.0, 1.5}) {
    Eigen::MatrixXd D = (scale * m.V * R.transpose()).rowwise() + Eigen::RowVector3d(0.3, -1, 2);
    for (const Eigen::Matrix3d& T : acap.deformation_gradients(D)) {
      EXPECT_LT((T - scale * R).norm(), 1e-6) << scale;
    }
    const Eigen::MatrixXd Q = acap.encode(D);
    const Eigen::AngleAxisd aa(R);
    for (Eigen::Index i = 0; i < Q.rows(); ++i) {
      ASSERT_LT((Q.row(i).head<3>().transpose() - aa.angle() * aa.axis()).norm(), 1e-6) << i;
      const Eigen::RowVectorXd S = Q.row(i).tail<6>();
      Eigen::RowVectorXd expected(6);
      expected << scale, 0, 0, scale, 0, scale;
      ASSERT_LT((S - expected).norm(), 1e-6) << i;
    }
    EXPECT_LT(max_distance(acap.decode(Q, D), D), 1e-6) << scale;
  }
  // The template itself: identity rotations, unit scale, and decoded in place.
  const Eigen::MatrixXd Q0 = acap.encode(m.V);
  EXPECT_LT(Q0.leftCols(3).norm(), 1e-6);
  EXPECT_LT(max_distance(acap.decode(Q0), m.V), 1e-6);
}

TEST(Acap, BentAndTwistedTubesRoundTrip) {
  const Mesh m = tube();
  const AcapEncoder acap(m, "tube");
  for (const auto& [name, D] : {std::pair<const char*, Eigen::MatrixXd>{"bent", bent(m)},
                                {"twisted 3/4 turn", twisted(m, 1.5 * M_PI)}}) {
    const Eigen::MatrixXd back = acap.decode(acap.encode(D), D);
    // The Poisson reconstruction is a least-squares fit of the per-vertex gradients: not exact
    // for a non-affine deformation, but within a small fraction of the tube's radius (0.1).
    EXPECT_LT(max_distance(back, D), 0.01) << name;
    EXPECT_LT((back - D).rowwise().norm().mean(), 0.003) << name;
  }
}

TEST(Acap, RotationsPastPiStayContinuousOverTheSequenceAndTheMesh) {
  const Mesh m = tube();
  const AcapEncoder acap(m, "tube");
  // The upper half turns rigidly by 0, 0.3π, ..., 3π over the sequence (twisted over
  // 0.3 ≤ z ≤ 0.5); the top's rotation vector must follow instead of wrapping at π.
  std::vector<Eigen::MatrixXd> frames;
  for (int k = 0; k <= 10; ++k) frames.push_back(twisted(m, 0.3 * M_PI * k, 0.3, 0.5));
  const std::vector<Eigen::MatrixXd> Q = acap.encode_sequence(frames);
  ASSERT_EQ(Q.size(), frames.size());
  const int top = (kRings - 1) * kSides;  // a vertex of the top ring (z = 1)
  for (std::size_t k = 0; k < Q.size(); ++k) {
    const Eigen::Vector3d expected(0, 0, 0.3 * M_PI * static_cast<double>(k));
    EXPECT_LT((Q[k].row(top).head<3>().transpose() - expected).norm(), 1e-6) << "frame " << k;
  }

  // A single mesh (a thin tube twisted by 1.5π along its length): consistent over the mesh,
  // from its least-rotated end, so the top's angle is 1.5π rather than the principal −0.5π.
  const Mesh thin =
      skinlab::testing::TubeBuilder().tube({0, 0, 0}, {0, 0, 1}, 0.03, kSides, kRings).build();
  const AcapEncoder thin_acap(thin, "thin tube");
  const Eigen::MatrixXd single = thin_acap.encode(twisted(thin, 1.5 * M_PI));
  EXPECT_NEAR(single(top, 2), 1.5 * M_PI, 0.05);
  double jump = 0;
  for (Eigen::Index f = 0; f < thin.F.rows(); ++f) {
    for (int e = 0; e < 3; ++e) {
      jump = std::max(jump, (single.row(thin.F(f, e)).head<3>() -
                             single.row(thin.F(f, (e + 1) % 3)).head<3>()).norm());
    }
  }
  EXPECT_LT(jump, 0.5);
}

TEST(Acap, EachConnectedPartIsPlacedWhereAsked) {
  const Mesh m = skinlab::testing::TubeBuilder()
                     .tube({0, 0, 0}, {0, 0, 1}, 0.1, kSides, kRings)
                     .tube({1, 0, 0}, {1, 0, 1}, 0.1, kSides, kRings)
                     .build();
  const AcapEncoder acap(m, "two tubes");
  ASSERT_EQ(acap.num_parts(), 2);
  // Each tube moved rigidly by its own translation: features cannot say where the parts are.
  Eigen::MatrixXd D = m.V;
  for (Eigen::Index i = 0; i < D.rows(); ++i) {
    D.row(i) += acap.parts()[static_cast<std::size_t>(i)] == 0 ? Eigen::RowVector3d(0, 0, 5)
                                                                : Eigen::RowVector3d(-2, 0, 0);
  }
  const Eigen::MatrixXd Q = acap.encode(D);
  EXPECT_LT(max_distance(acap.decode(Q, D), D), 1e-6);
  EXPECT_LT(max_distance(acap.decode(Q), m.V), 1e-6);  // default: the template's placement
}

TEST(FeatureScale, MapsEveryEntryIntoTheBoundAndBack) {
  std::vector<Eigen::MatrixXd> frames = {Eigen::MatrixXd::Random(5, 9), Eigen::MatrixXd::Random(5, 9),
                                         Eigen::MatrixXd::Random(5, 9)};
  for (auto& f : frames) f.col(4).setConstant(0.25);  // a constant entry
  const FeatureScale s = FeatureScale::fit(frames);
  Eigen::MatrixXd lo = Eigen::MatrixXd::Constant(5, 9, 1e9), hi = -lo;
  for (const auto& f : frames) {
    const Eigen::MatrixXd n = s.normalise(f);
    lo = lo.cwiseMin(n);
    hi = hi.cwiseMax(n);
    EXPECT_LT((s.denormalise(n) - f).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_TRUE(n.col(4).isZero());
  }
  lo.col(4).setConstant(-0.95);
  hi.col(4).setConstant(0.95);
  EXPECT_LT((lo.array() + 0.95).abs().maxCoeff(), 1e-12);  // every entry reaches both bounds
  EXPECT_LT((hi.array() - 0.95).abs().maxCoeff(), 1e-12);
  expect_error<Error>([&] { s.normalise(Eigen::MatrixXd::Zero(4, 9)); }, {"4×9", "5×9"});
  expect_error<Error>([&] { FeatureScale::fit({frames[0], Eigen::MatrixXd::Zero(5, 8)}); },
                      {"frame 1", "5×8"});
  expect_error<Error>([&] { FeatureScale::fit({}); }, {"no frames"});
}

TEST(Acap, BadInputNamesTheVertex) {
  const Mesh m = tube();
  const AcapEncoder acap(m, "tube.obj");
  Eigen::MatrixXd D = m.V;
  D(17, 1) = std::nan("");
  expect_error<GeometryError>([&] { acap.encode(D); }, {"tube.obj", "vertex 17", "non-finite"});
  expect_error<GeometryError>([&] { acap.encode(m.V.topRows(10)); }, {"tube.obj", "10×3"});
  Eigen::MatrixXd Q = acap.encode(m.V);
  Q(3, 8) = INFINITY;
  expect_error<GeometryError>([&] { acap.decode(Q); }, {"feature matrix", "vertex 3"});
  Mesh lonely = m;
  lonely.V.conservativeResize(m.V.rows() + 1, 3);
  lonely.V.row(m.V.rows()) = Eigen::RowVector3d(5, 5, 5);
  expect_error<GeometryError>([&] { AcapEncoder(lonely, "lonely.obj"); },
                              {"lonely.obj", "vertex " + std::to_string(m.V.rows()), "no edge"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

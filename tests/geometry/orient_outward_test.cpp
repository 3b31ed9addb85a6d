// orient_outward: parts wound inwards are flipped, parts wound outwards are kept, per part.

#include "framework/geometry/orient_outward.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "tests/geometry/test_meshes.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

/// A closed unit-ish tetrahedron at `offset`, wound outwards (or inwards when `inwards`).
void add_tetrahedron(Eigen::MatrixXd& V, Eigen::MatrixXi& F, const Eigen::Vector3d& offset,
                     bool inwards) {
  const int base = static_cast<int>(V.rows());
  V.conservativeResize(base + 4, 3);
  V.row(base) = offset.transpose();
  V.row(base + 1) = (offset + Eigen::Vector3d(1, 0, 0)).transpose();
  V.row(base + 2) = (offset + Eigen::Vector3d(0, 1, 0)).transpose();
  V.row(base + 3) = (offset + Eigen::Vector3d(0, 0, 1)).transpose();
  const int f = static_cast<int>(F.rows());
  F.conservativeResize(f + 4, 3);
  // Outward: normals away from the interior point (0.25, 0.25, 0.25).
  F.row(f) << base, base + 2, base + 1;
  F.row(f + 1) << base, base + 1, base + 3;
  F.row(f + 2) << base, base + 3, base + 2;
  F.row(f + 3) << base + 1, base + 2, base + 3;
  if (inwards) {
    for (int k = 0; k < 4; ++k) std::swap(F(f + k, 1), F(f + k, 2));
  }
}

double signed_volume(const Mesh& m, int first_face, int faces) {
  return testing::signed_volume(m.V, m.F, first_face, faces);
}

TEST(OrientOutward, FlipsOnlyThePartsWoundInwards) {
  Mesh m;
  m.V.resize(0, 3);
  m.F.resize(0, 3);
  add_tetrahedron(m.V, m.F, {0, 0, 0}, false);
  add_tetrahedron(m.V, m.F, {3, 0, 0}, true);
  add_tetrahedron(m.V, m.F, {-5, 2, 7}, true);  // far from the origin: the centroid is used
  ASSERT_GT(signed_volume(m, 0, 4), 0);
  ASSERT_LT(signed_volume(m, 4, 4), 0);
  OrientReport report;
  const Mesh out = orient_outward(m, &report);
  EXPECT_EQ(report.parts, 3);
  EXPECT_EQ(report.flipped_parts, 2);
  EXPECT_EQ(out.V, m.V);
  EXPECT_EQ(out.F.topRows(4), m.F.topRows(4));
  for (int part = 0; part < 3; ++part) {
    EXPECT_NEAR(signed_volume(out, 4 * part, 4), 1.0 / 6, 1e-12) << "part " << part;
  }
  // Idempotent.
  OrientReport again;
  EXPECT_EQ(orient_outward(out, &again).F, out.F);
  EXPECT_EQ(again.flipped_parts, 0);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

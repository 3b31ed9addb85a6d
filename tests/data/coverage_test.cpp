// Candidate coverage (HeterSkinNet Fig. 6): weight and influential-entry shares on the K nearest
// bones, and the diagnosis of missed entries, counted by hand on a three-joint chain.

#include <gtest/gtest.h>

#include "framework/data/coverage.hpp"
#include "tests/test_util.hpp"

namespace skinlab::data {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

/// root (0) → mid (1) → leaf (2); bones b0 = root→mid, b1 = mid→leaf, b2 = the leaf's helper.
/// Two vertices with distances v0: [1, 2, 3], v1: [3, 2, 2] (b1 and b2 tie).
PreparedCharacter chain(double v0_root) {
  PreparedCharacter c;
  c.name = "chain";
  c.V = RowMatrixXd::Zero(2, 3);
  c.joint_names = {"root", "mid", "leaf"};
  c.parents = {-1, 0, 1};
  c.joints = RowMatrixXd(3, 3);
  c.joints << 0, 0, 0, 0, 1, 0, 0, 2, 0;
  c.bones = RowMatrixXi(3, 2);
  c.bones << 0, 1, 1, 2, 2, 2;
  c.weights.resize(2, 3);
  if (v0_root > 0) c.weights.insert(0, 0) = v0_root;
  c.weights.insert(0, 1) = 1 - v0_root;
  c.weights.insert(1, 1) = 0.5;
  c.weights.insert(1, 2) = 0.5;
  c.weights.makeCompressed();
  DistanceData d;
  d.D = RowMatrixXf(2, 3);
  d.D << 1, 2, 3, 3, 2, 2;
  c.distances.emplace("euclidean", d);
  return c;
}

TEST(CandidateCoverage, SharesPerKByHand) {
  const Coverage cov = candidate_coverage(chain(0.7), "euclidean", 3, 1);
  EXPECT_EQ(cov.entries, 4);
  EXPECT_DOUBLE_EQ(cov.weight, 2.0);
  EXPECT_EQ(cov.vertices, 2);
  // K = 1: v0 keeps root's 0.7 (b0), v1 keeps mid's 0.5 (b1 before b2 on the tie).
  EXPECT_DOUBLE_EQ(cov.weight_share(1), 0.6);
  EXPECT_DOUBLE_EQ(cov.entry_share(1), 0.5);
  EXPECT_DOUBLE_EQ(cov.weight_share(2), 1.0);
  EXPECT_DOUBLE_EQ(cov.entry_share(2), 1.0);
  EXPECT_DOUBLE_EQ(cov.entry_share(3), 1.0);
  // Missed at K = 1: v0's b1 (not tied: 2 vs 1) and v1's helper b2 (tied with b1 at 2).
  EXPECT_EQ(cov.missed, 2);
  EXPECT_EQ(cov.missed_helper, 1);
  EXPECT_EQ(cov.missed_tied, 1);
  EXPECT_EQ(cov.slots, 2);
  EXPECT_EQ(cov.weightless_slots, 0);
}

TEST(CandidateCoverage, WeightlessJointsTakingSlotsAndAddingUp) {
  // The root carries no weight: v0's nearest bone b0 is a weightless slot.
  Coverage cov = candidate_coverage(chain(0.0), "euclidean", 3, 1);
  EXPECT_EQ(cov.weightless_slots, 1);
  EXPECT_DOUBLE_EQ(cov.weight_share(1), 0.25);  // only v1's 0.5 of 2
  cov.add(candidate_coverage(chain(0.7), "euclidean", 3, 1));
  EXPECT_EQ(cov.entries, 7);
  EXPECT_EQ(cov.slots, 4);
  EXPECT_DOUBLE_EQ(cov.weight_share(1), (0.5 + 1.2) / 4.0);
  testing::expect_error<Error>([&] { cov.add(candidate_coverage(chain(0.7), "euclidean", 4, 1)); },
                               {"K ranges differ"});
}

TEST(CandidateCoverage, BadRequestsAreNamed) {
  const PreparedCharacter c = chain(0.7);
  testing::expect_error<Error>([&] { candidate_coverage(c, "hollow_dist", 3, 1); },
                               {"chain", "hollow_dist"});
  testing::expect_error<Error>([&] { candidate_coverage(c, "euclidean", 3, 4); }, {"diagnose_k"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::data

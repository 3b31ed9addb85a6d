// The paired t-test against values computed independently: t by hand, and p from the closed
// forms of Student's t tail for 1 and 3 degrees of freedom (two-sided p = 1 − (2/π)·atan|t| for
// one; 1 − (2/π)·(atan x + x / (1 + x²)) with x = |t|/√3 for three).

#include <gtest/gtest.h>

#include <cmath>

#include "framework/core/error.hpp"
#include "framework/eval/paired_t.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

TEST(PairedT, FourPairsByHand) {
  // differences 1, 2, 3, 4: mean 2.5, sd √(5/3), t = 2.5 / (sd / 2) = √15
  const eval::PairedT r = eval::paired_t_test({0, 0, 0, 0}, {1, 2, 3, 4});
  EXPECT_EQ(r.pairs, 4);
  EXPECT_NEAR(r.mean_difference, 2.5, 1e-12);
  EXPECT_NEAR(r.t, std::sqrt(15.0), 1e-12);
  const double x = r.t / std::sqrt(3.0);
  EXPECT_NEAR(r.p, 1 - 2 / M_PI * (std::atan(x) + x / (1 + x * x)), 1e-12);
  // the sign follows b − a; p does not
  const eval::PairedT back = eval::paired_t_test({1, 2, 3, 4}, {0, 0, 0, 0});
  EXPECT_NEAR(back.t, -r.t, 1e-12);
  EXPECT_NEAR(back.p, r.p, 1e-12);
}

TEST(PairedT, PairingRemovesTheSpreadOverCharactersAndNanDropsAPair) {
  // values spread widely over characters, b a little above a everywhere: the ANOVA would see
  // the spread; the paired test sees differences 0.1, 0.2 (t = 0.15 / 0.05 = 3, one dof)
  const eval::PairedT r = eval::paired_t_test({0.1, 0.9, NAN}, {0.2, 1.1, 0.5});
  EXPECT_EQ(r.pairs, 2);
  EXPECT_NEAR(r.t, 3.0, 1e-9);
  EXPECT_NEAR(r.p, 1 - 2 / M_PI * std::atan(3.0), 1e-9);
}

TEST(PairedT, ConstantDifferencesAndBadInputs) {
  const eval::PairedT up = eval::paired_t_test({0.25, 0.5}, {0.75, 1.0});
  EXPECT_TRUE(std::isinf(up.t));
  EXPECT_GT(up.t, 0);
  EXPECT_EQ(up.p, 0.0);
  const eval::PairedT none = eval::paired_t_test({1, 2}, {1, 2});
  EXPECT_TRUE(std::isnan(none.t));
  EXPECT_TRUE(std::isnan(none.p));
  using testing::expect_error;
  expect_error<Error>([] { eval::paired_t_test({1, 2}, {1, 2, 3}); }, {"2 values against 3"});
  expect_error<Error>([] { eval::paired_t_test({1, NAN}, {1, 2}); }, {"1 pairs", "at least two"});
  expect_error<Error>([] { eval::paired_t_test({1, INFINITY}, {1, 2}); },
                      {"character 1 has an infinite value"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

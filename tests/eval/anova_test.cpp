// One-way ANOVA against values computed independently: F by hand, p from the t density
// integrated numerically (two groups: F(1, ν) = t²) and from the closed form of the F(2, ν)
// upper tail, (1 + 2F/ν)^(−ν/2).

#include <gtest/gtest.h>

#include <cmath>

#include "framework/core/error.hpp"
#include "framework/eval/anova.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

TEST(Anova, TwoGroupsByHand) {
  // means 2 and 5, grand mean 3.5: SS_between = 2·3·1.5² = 13.5, SS_within = 2 + 2 = 4.
  const eval::Anova a = eval::one_way_anova({{1, 2, 3}, {4, 5, 6}});
  EXPECT_EQ(a.df_between, 1);
  EXPECT_EQ(a.df_within, 4);
  EXPECT_NEAR(a.F, 13.5, 1e-12);
  EXPECT_NEAR(a.p, 0.02131164112875623, 1e-9);
}

TEST(Anova, ThreeGroupsUnequalSizes) {
  const eval::Anova a =
      eval::one_way_anova({{2, 3, 7, 4}, {6, 8, 9}, {1, 2.5, 3.5, 2, 1}});
  EXPECT_EQ(a.df_between, 2);
  EXPECT_EQ(a.df_within, 9);
  EXPECT_NEAR(a.F, 11.703237410071942, 1e-10);
  EXPECT_NEAR(a.p, std::pow(1 + 2 * a.F / 9, -4.5), 1e-12);
  EXPECT_NEAR(a.p, 0.0031350771520034125, 1e-12);
}

TEST(Anova, OrderOfGroupsDoesNotMatterAndIdenticalGroupsGiveFZero) {
  const eval::Anova ab = eval::one_way_anova({{0.1, 0.4, 0.3}, {0.5, 0.9}});
  const eval::Anova ba = eval::one_way_anova({{0.5, 0.9}, {0.1, 0.4, 0.3}});
  EXPECT_NEAR(ab.F, ba.F, 1e-12);  // (sums in another order: equal up to rounding)
  EXPECT_NEAR(ab.p, ba.p, 1e-12);
  const eval::Anova same = eval::one_way_anova({{1, 2, 3}, {3, 2, 1}});
  EXPECT_DOUBLE_EQ(same.F, 0.0);
  EXPECT_DOUBLE_EQ(same.p, 1.0);
  const eval::Anova constant = eval::one_way_anova({{1, 1}, {2, 2}});
  EXPECT_TRUE(std::isinf(constant.F));
  EXPECT_EQ(constant.p, 0.0);
}

TEST(Anova, BadInputsAreErrors) {
  using testing::expect_error;
  expect_error<Error>([] { eval::one_way_anova({{1, 2}}); }, {"at least two groups"});
  expect_error<Error>([] { eval::one_way_anova({{1, 2}, {}}); }, {"group 1 is empty"});
  expect_error<Error>([] { eval::one_way_anova({{1}, {2}}); }, {"no degrees of freedom"});
  expect_error<Error>([] { eval::one_way_anova({{1, NAN}, {2, 3}}); },
                      {"group 0 has a non-finite value"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

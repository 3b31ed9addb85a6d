#pragma once
/// \file
/// One-way analysis of variance, as HeterSkinNet Sec. 4.5 / Fig. 9 uses to compare its
/// per-character test metrics with RigNet's ("for precision F = 4.5259, p = 0.0346"). Groups are
/// the per-character values of one metric for each method; with two groups F equals the square
/// of the pooled-variance t statistic.
///
///     SS_between = Σ_g n_g (mean_g − mean)²,  df_between = G − 1
///     SS_within  = Σ_g Σ_i (x_gi − mean_g)²,  df_within  = N − G
///     F = (SS_between / df_between) / (SS_within / df_within),  p = P(F(df_b, df_w) > F)
///
/// The upper tail of the F distribution is Boost.Math's (`fisher_f`, installed with libcgal-dev).

#include <vector>

namespace skinlab::eval {

struct Anova {
  double F = 0;
  double p = 1;
  int df_between = 0;
  int df_within = 0;
};

/// Throws Error for fewer than two groups, an empty group, fewer than G + 1 values in all,
/// or a non-finite value. Identical values everywhere (SS_within = 0) give F = +inf and p = 0
/// when the means differ, F = NaN and p = NaN when they do not.
Anova one_way_anova(const std::vector<std::vector<double>>& groups);

}  // namespace skinlab::eval

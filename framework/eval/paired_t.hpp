#pragma once
/// \file
/// Paired t-test of two methods' per-character values of one metric on the same characters.
///
/// HeterSkinNet Sec. 4.5 compares methods with a one-way ANOVA over characters (eval/anova.hpp),
/// which treats the two methods' values as independent samples. They are not: both methods are
/// scored on the same characters, and most of the spread over characters (an easy character is
/// easy for every method) cancels in the per-character difference. The paired test uses only
/// those differences, so `skinlab table` reports it beside the paper's ANOVA:
///
///     d_i = b_i − a_i  (characters where both values are defined),  n pairs
///     t = mean(d) / (sd(d) / √n),  df = n − 1,  p = 2 · P(T(df) > |t|)  (two-sided)
///
/// The tail of Student's t distribution is Boost.Math's (`students_t`, installed with libcgal-dev).

#include <vector>

namespace skinlab::eval {

struct PairedT {
  double t = 0;      ///< positive when b is larger on average
  double p = 1;      ///< two-sided
  double mean_difference = 0;  ///< mean of b − a
  int pairs = 0;
};

/// `a` and `b` hold one value per character, in the same order; a NaN in either (a metric
/// undefined for that character) drops the pair. Throws Error when the lengths differ, a value is
/// infinite, or fewer than two pairs remain. Identical differences everywhere (sd = 0) give
/// t = ±inf and p = 0 when they are not zero, t = NaN and p = NaN when they are.
PairedT paired_t_test(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace skinlab::eval

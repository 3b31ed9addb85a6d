#include "framework/eval/anova.hpp"

#include <boost/math/distributions/fisher_f.hpp>
#include <cmath>
#include <limits>
#include <string>

#include "framework/core/error.hpp"

namespace skinlab::eval {

Anova one_way_anova(const std::vector<std::vector<double>>& groups) {
  if (groups.size() < 2) throw Error("one-way ANOVA needs at least two groups");
  double total = 0;
  std::size_t n = 0;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (groups[g].empty()) throw Error("one-way ANOVA: group " + std::to_string(g) + " is empty");
    for (double x : groups[g]) {
      if (!std::isfinite(x)) {
        throw Error("one-way ANOVA: group " + std::to_string(g) + " has a non-finite value");
      }
      total += x;
    }
    n += groups[g].size();
  }
  if (n <= groups.size()) {
    throw Error("one-way ANOVA: " + std::to_string(n) + " values in " +
                std::to_string(groups.size()) + " groups leave no degrees of freedom within");
  }
  const double grand = total / static_cast<double>(n);
  double between = 0, within = 0;
  for (const auto& group : groups) {
    double sum = 0;
    for (double x : group) sum += x;
    const double mean = sum / static_cast<double>(group.size());
    between += static_cast<double>(group.size()) * (mean - grand) * (mean - grand);
    for (double x : group) within += (x - mean) * (x - mean);
  }
  Anova a;
  a.df_between = static_cast<int>(groups.size()) - 1;
  a.df_within = static_cast<int>(n - groups.size());
  const double ms_between = between / a.df_between, ms_within = within / a.df_within;
  if (ms_within == 0) {
    const bool differ = ms_between > 0;
    a.F = differ ? std::numeric_limits<double>::infinity() : std::nan("");
    a.p = differ ? 0.0 : std::nan("");
    return a;
  }
  a.F = ms_between / ms_within;
  const boost::math::fisher_f_distribution<double> f(a.df_between, a.df_within);
  a.p = boost::math::cdf(boost::math::complement(f, a.F));
  return a;
}

}  // namespace skinlab::eval

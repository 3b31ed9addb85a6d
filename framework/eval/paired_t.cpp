#include "framework/eval/paired_t.hpp"

#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <limits>
#include <string>

#include "framework/core/error.hpp"

namespace skinlab::eval {

PairedT paired_t_test(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) {
    throw Error("paired t-test: " + std::to_string(a.size()) + " values against " +
                std::to_string(b.size()) + "; pairs need one value of each per character");
  }
  std::vector<double> d;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::isinf(a[i]) || std::isinf(b[i])) {
      throw Error("paired t-test: character " + std::to_string(i) + " has an infinite value");
    }
    if (!std::isnan(a[i]) && !std::isnan(b[i])) d.push_back(b[i] - a[i]);
  }
  if (d.size() < 2) {
    throw Error("paired t-test: " + std::to_string(d.size()) +
                " pairs with both values defined; it needs at least two");
  }
  PairedT r;
  r.pairs = static_cast<int>(d.size());
  const double n = static_cast<double>(d.size());
  for (double x : d) r.mean_difference += x;
  r.mean_difference /= n;
  double ss = 0;
  for (double x : d) ss += (x - r.mean_difference) * (x - r.mean_difference);
  const double se = std::sqrt(ss / (n - 1)) / std::sqrt(n);
  if (se == 0) {
    const bool differ = r.mean_difference != 0;
    r.t = differ ? std::copysign(std::numeric_limits<double>::infinity(), r.mean_difference)
                 : std::nan("");
    r.p = differ ? 0.0 : std::nan("");
    return r;
  }
  r.t = r.mean_difference / se;
  const boost::math::students_t_distribution<double> t(n - 1);
  r.p = 2 * boost::math::cdf(boost::math::complement(t, std::fabs(r.t)));
  return r;
}

}  // namespace skinlab::eval

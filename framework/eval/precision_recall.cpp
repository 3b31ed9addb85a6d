#include "framework/eval/precision_recall.hpp"

#include <cmath>

#include "framework/core/registry.hpp"
#include "framework/eval/value_display.hpp"
#include "framework/eval/weights.hpp"

namespace skinlab::eval {

PrecisionRecall::Options PrecisionRecall::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "metric 'precision_recall'");
  f.optional("threshold", o.threshold)
      .check(o.threshold >= 0 && o.threshold < 1, "threshold", "must be in [0, 1)");
  f.optional("prune", o.prune).check(o.prune >= 0 && o.prune <= 1, "prune", "must be in [0, 1]");
  std::string average = "entries";
  f.optional("average", average)
      .check(average == "entries" || average == "vertices", "average",
             "must be 'entries' or 'vertices', got '" + average + "'");
  o.average = average == "entries" ? Average::kEntries : Average::kVertices;
  f.finish();
  return o;
}

std::map<std::string, double> PrecisionRecall::operator()(const MetricInputs& in) const {
  auto [P, G] = read_weights(in, "precision_recall");
  prune_rows(P, options_.prune);
  const double t = options_.threshold;
  const auto ratio = [](double num, double den) { return den > 0 ? num / den : 0.0; };
  double both = 0, predicted = 0, actual = 0;  // entries: counts; vertices: sums of ratios
  for (Eigen::Index v = 0; v < P.rows(); ++v) {
    double row_both = 0, row_predicted = 0, row_actual = 0;
    for (Eigen::Index b = 0; b < P.cols(); ++b) {
      const bool p = P(v, b) > t, g = G(v, b) > t;
      row_both += p && g, row_predicted += p, row_actual += g;
    }
    if (options_.average == Average::kEntries) {
      both += row_both, predicted += row_predicted, actual += row_actual;
    } else {
      both += ratio(row_both, row_predicted), actual += ratio(row_both, row_actual);
    }
  }
  if (options_.average == Average::kEntries) {
    return {{"precision", ratio(both, predicted)}, {"recall", ratio(both, actual)}};
  }
  const double n = static_cast<double>(P.rows());
  return {{"precision", ratio(both, n)}, {"recall", ratio(actual, n)}};
}

}  // namespace skinlab::eval

SKINLAB_DECLARE_VALUE({"precision", "Precision", "", true, true, 2});
SKINLAB_DECLARE_VALUE({"recall", "Recall", "", true, true, 2});
SKINLAB_REGISTER(metric, precision_recall, skinlab::eval::PrecisionRecall);

#pragma once
/// \file
/// `avg_l1`: numerical accuracy of the weights (HeterSkinNet Sec. 4.3, "L1-norm": "a character
/// model's L1-norm is the average of L1-norms over its vertices"; RigNet's "avg L1"). Output
/// "avg_l1", in [0, 2] for rows summing to 1:
///
///     avg_l1 = (1 / #V) Σ_v Σ_b |P(v, b) − G(v, b)|
///
/// over all #B bones of the character (not only a vertex's K candidates: weight a method puts
/// on, or misses from, any bone counts). The evaluator averages it over characters.
///
/// P is the pruned prediction (weights.hpp prune_rows, default `prune` = 0.25), the same final
/// weights precision_recall and deformation_error judge. The paper does not say whether its L1
/// is taken before or after pruning; Sec. 4.5 makes pruning part of every compared method's
/// output, RigNet's run_skinning.py writes out only pruned weights (after its one-ring filter, at
/// 0.5 × the row maximum), and Puppeteer's skinning/main.py computes the L1 on the pruned,
/// renormalised prediction. `prune: 0` gives the L1 of the raw prediction.

#include <Eigen/Core>

#include "framework/core/config.hpp"
#include "framework/eval/metric.hpp"

namespace skinlab::eval {

class AvgL1 final : public Metric {
 public:
  struct Options {
    double prune = 0.25;  ///< fraction of the row maximum below which P is zeroed; [0, 1]
    static Options from(const config::Node& node);
  };
  explicit AvgL1(Options options) : options_(options) {}
  std::map<std::string, double> operator()(const MetricInputs& in) const override;
  std::vector<std::string> names() const override { return {"avg_l1"}; }
  /// #V per-vertex errors Σ_b |P(v, b) − G(v, b)| (pruned P), whose mean is avg_l1: the
  /// per-vertex L1 maps of Fig. 7 and 10. Throws as operator() does.
  Eigen::VectorXd vertex_errors(const MetricInputs& in) const;

 private:
  Options options_;
};

}  // namespace skinlab::eval

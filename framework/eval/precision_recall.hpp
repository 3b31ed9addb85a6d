#pragma once
/// \file
/// `precision_recall`: how well a prediction finds the bones that influence each vertex
/// (HeterSkinNet Sec. 4.3, "Precision and Recall"; RigNet Sec. 7). Outputs "precision" and
/// "recall", fractions in [0, 1].
///
/// Definition, for one character with #V×#B predicted weights P and ground truth G:
/// 1. P is pruned as the compared methods prune their output (Sec. 4.5, "0.25 weight pruning
///    threshold"; weights.hpp prune_rows): in each row, weights below `prune` × the row maximum
///    become 0 and the row is renormalised. Default prune = 0.25; 0 disables it.
/// 2. Bone b influences vertex v when its weight exceeds `threshold` (Sec. 4.2: w > 1e-4):
///    pred(v, b) = P(v, b) > threshold, gt(v, b) = G(v, b) > threshold. Default 1e-4.
/// 3. `average: entries` (default), the RigNet-lineage convention (Puppeteer's
///    skinning/main.py): counted over all #V×#B entries of the character,
///        precision = |pred ∧ gt| / |pred|,   recall = |pred ∧ gt| / |gt|.
///    `average: vertices`: the same ratio per vertex (over its #B entries), then the mean over
///    vertices. A zero denominator gives 0 (as Puppeteer's `/ (n + 1e-10)` does).
/// The evaluator then averages the per-character values over the characters of a split
/// (evaluate.hpp), so a large character weighs as much as a small one.
///
/// The ground truth is not pruned, and there is no option to prune it: Sec. 4.2 defines an
/// influential bone on the artist weights by the threshold alone, Sec. 4.5 lists the pruning
/// threshold among the hyper-parameters of the compared methods (a post-processing of their
/// predictions), and Puppeteer's evaluation prunes only the prediction. Puppeteer counts any
/// ground-truth weight > 0; we use 1e-4 for both sides as Sec. 4.2 does (after pruning at 0.25
/// a predicted weight is ≥ 0.25 / #B, far above 1e-4, so the threshold matters on the ground-truth
/// side only).

#include "framework/core/config.hpp"
#include "framework/eval/metric.hpp"

namespace skinlab::eval {

class PrecisionRecall final : public Metric {
 public:
  enum class Average { kEntries, kVertices };
  struct Options {
    double threshold = 1e-4;  ///< a weight above this is an influence; in [0, 1)
    double prune = 0.25;      ///< fraction of the row maximum below which P is zeroed; [0, 1]
    Average average = Average::kEntries;  ///< `entries` or `vertices`
    static Options from(const config::Node& node);
  };
  explicit PrecisionRecall(Options options) : options_(options) {}
  std::map<std::string, double> operator()(const MetricInputs& in) const override;
  std::vector<std::string> names() const override { return {"precision", "recall"}; }
  const Options& options() const { return options_; }

 private:
  Options options_;
};

}  // namespace skinlab::eval

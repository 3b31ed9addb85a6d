#pragma once
/// \file
/// `dominant_joint`: does a prediction give each vertex to the joint the artist gave it, and
/// where a leaf joint dominates (a head, a hand, a foot, a tail tip), does it give the vertex to
/// the leaf's parent instead? Not a metric of the paper; the failure it counts is the one a
/// zero-length helper bone invites (distances/leaf_bones.hpp). Outputs, fractions in [0, 1]:
///
/// - `dominant_joint`: the share of vertices whose predicted dominant joint (the joint with the
///   largest weight, bone weights mapped back to joints as weights.hpp joint_weights; ties: lower
///   joint index) is the artist's dominant joint. Vertices without artist weight are left out.
/// - `leaf_to_parent`: among the vertices whose artist dominant joint is a leaf (a joint without
///   children), the share whose predicted dominant joint is that leaf's parent. NaN for a
///   character without such vertices: the evaluator and the tables leave a NaN out of a mean
///   (evaluate.hpp), so the split's value is the mean over the characters that have leaf
///   vertices.
///
/// The prediction is pruned first (weights.hpp prune_rows, default `prune` = 0.25), the same
/// final weights the other metrics judge: pruning keeps each row's largest bone weight, but it can
/// drop small bones of a joint whose bones together outweigh another joint.

#include "framework/core/config.hpp"
#include "framework/eval/metric.hpp"

namespace skinlab::eval {

class DominantJoint final : public Metric {
 public:
  struct Options {
    double prune = 0.25;  ///< fraction of the row maximum below which P is zeroed; [0, 1]
    static Options from(const config::Node& node);
  };
  explicit DominantJoint(Options options) : options_(options) {}
  std::map<std::string, double> operator()(const MetricInputs& in) const override;
  std::vector<std::string> names() const override { return {"dominant_joint", "leaf_to_parent"}; }

 private:
  Options options_;
};

}  // namespace skinlab::eval

#include "framework/models/branched_model.hpp"

namespace skinlab::models {

void BranchedModelOptions::read(config::Fields& f) {
  f.optional("top_k", top_k);
  f.optional("distance_unit", distance_unit);
  f.optional("min_distance", min_distance);
  stem = f.section("stem");
  local = f.section("local");
  global = f.section("global");
  f.optional("head", head);
  f.optional("head_dropout", head_dropout);
  f.check(top_k >= 1, "top_k", "must be ≥ 1");
  f.check(distance_unit > 0, "distance_unit", "must be positive");
  f.check(min_distance > 0, "min_distance", "must be positive");
  for (auto w : head) f.check(w >= 1, "head", "widths must be ≥ 1");
  f.check(head_dropout >= 0 && head_dropout < 1, "head_dropout", "must be in [0, 1)");
}

void BranchedModelOptions::fill_missing_branches(const config::Config& defaults) {
  if (!stem.exists()) stem = defaults.root()["stem"];
  if (!local.exists()) local = defaults.root()["local"];
  if (!global.exists()) global = defaults.root()["global"];
}

torch::Tensor inverse_distance(const torch::Tensor& topk_distance,
                               const BranchedModelOptions& options) {
  return (topk_distance / options.distance_unit).clamp_min(options.min_distance).reciprocal();
}

}  // namespace skinlab::models

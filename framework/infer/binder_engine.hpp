#pragma once
/// \file
/// A classical method in place of the network (`skinlab predict --binder bone_heat`): the
/// weights of a `binder` plug-in (framework/binders/binder.hpp: bone heat, GeoVoxel) for a
/// character of one's own, prepared exactly as a model's inputs are (the model directory's
/// preparation: normalise, merge co-located vertices, subdivide, leaf bones; infer/prediction.hpp
/// steps 1–2), then pruned at the same fraction of the row maximum and mapped back to the
/// input's vertices and joints (step 4). So a binder and a model written by `predict` differ
/// only in the weights at the prepared vertices, as their rows of `skinlab eval` do, and
/// `skinlab score` compares them on the same footing (scripts/compare_blender's "our bone heat"
/// row beside Blender's own automatic weights).
///
/// The binder is given as a registry key with its default options (`bone_heat`), as YAML flow
/// text (`{type: bone_heat, closest: blender}`), or as a config file with a `binder:` section
/// (configs/baselines/bone_heat.yaml). Only the model directory's preparation and distance are
/// read (the distance names the bones' candidate lists, which the truth's bone-level rule uses
/// when an input's own weights are compared); its network and priors are not.

#include <filesystem>
#include <memory>
#include <string>

#include "framework/infer/engine.hpp"

namespace skinlab::binders {
class Binder;
}

namespace skinlab::infer {

class BinderEngine final : public PredictEngine {
 public:
  /// The binder `spec` (see the file comment) with the preparation of the model directory
  /// `dir` (a run directory or a bundled model: preparation.yaml or its data file's
  /// preparation). ConfigError naming the spec or file for an unknown binder type, a config
  /// without `binder:`, a reference row of `skinlab eval` (artist_weights and the like, which
  /// need the dataset file), or bad options; IoError for a missing model directory or
  /// preparation.
  static BinderEngine load(const std::string& spec, const std::filesystem::path& dir);

  Prediction predict(const geometry::Character& character, const PredictOptions& options = {},
                     StageTimes* times = nullptr) const override;
  /// "binder 'bone_heat' on the preparation of results/bundled/heterskinnet".
  const std::string& description() const override { return description_; }
  const std::string& distance() const override { return preparation_.distance(); }

 private:
  BinderEngine() = default;
  std::shared_ptr<const binders::Binder> binder_;
  std::string type_;
  Preparation preparation_;
  std::string description_;
};

}  // namespace skinlab::infer

#pragma once
/// \file
/// Interface of the `binder` registry: skinning methods that compute weights from the geometry
/// alone, without training (HeterSkinNet Table 3's GeoVoxel, Dionne & de Lasa 2013; Blender's
/// bone heat, Baran & Popović 2007). They are evaluated by the same pipeline and metrics as the
/// learned models (`skinlab eval <config>` on a config with a `binder:` section), so a table row
/// of a binder and of a network mean the same thing.
///
///     binder: {type: geo_voxel, resolution: 128, falloff: 0.5, max_influences: 3}
///
/// Implementations live in `baselines/<key>/<key>.{hpp,cpp}` and register with
/// `SKINLAB_REGISTER(binder, <key>, Class)`.

#include <string>

#include <Eigen/Core>

#include "framework/core/config.hpp"
#include "framework/geometry/mesh.hpp"
#include "framework/geometry/skeleton.hpp"

namespace skinlab::binders {

class Binder {
 public:
  virtual ~Binder() = default;
  /// #V×#B bone weights (bones in `Skeleton::bones()` order, the order of a prepared
  /// character's `bones`): every entry ≥ 0 and every row sums to 1. The mesh is in the
  /// normalised frame (1 m tall, Y up). Throws GeometryError naming the vertex (or bone) when a
  /// vertex cannot be bound: never a silent zero row.
  virtual Eigen::MatrixXd bind(const geometry::Mesh& mesh,
                               const geometry::Skeleton& skeleton) const = 0;
};

/// Three `binder:` types that are not binders, and not in the registry, computed by the
/// evaluator (eval/evaluator.hpp) from the dataset file. Two are the reference itself, scored as
/// a prediction: the ceilings of the metrics.
/// `artist_weights`: the artist's own #V×#B weights, pruned by each metric like any prediction
/// (precision 1; recall is the share of influential entries that survive `prune`).
inline constexpr const char* kArtistWeights = "artist_weights";
/// `artist_candidates`: the training targets, the artist's weights on the K candidate bones
/// renormalised (data/preprocess.hpp step 4): the best a K-candidate network can output.
inline constexpr const char* kArtistCandidates = "artist_candidates";
/// `prior_on_candidates` (with `prior: <binder type>`): a prior stored in the dataset file
/// (data/preprocess.hpp step 4b) on the K candidates, renormalised (uniform where it is 0 on all
/// K): what a model reading that prior starts from (HeterSkinNet with a zero head, up to its
/// prior_epsilon), and a classical method restricted to the candidates of `data.distance`.
inline constexpr const char* kPriorOnCandidates = "prior_on_candidates";
/// Whether a `binder:` type is one of the three rows above, which the evaluator computes itself.
inline bool is_reference_row(const std::string& type) {
  return type == kArtistWeights || type == kArtistCandidates || type == kPriorOnCandidates;
}
/// Checks the fields of a reference row's node (`type`, and `prior` for prior_on_candidates;
/// ConfigError naming the node for a missing or unknown field) and returns its `prior` (empty
/// for the other two). Called when a config is read and by the evaluator.
std::string reference_row_prior(const config::Node& node);

/// `binder.bind(mesh, skeleton)`, checked against the contract of Binder::bind: #V×#B (#B =
/// `skeleton.bones().size()`), entries ≥ 0, rows summing to 1 within 1e-4. Throws Error starting
/// with `what` (the binder and the character) and naming the first bad vertex. Every caller of a
/// binder (the evaluator, the dataset's priors, `predict --binder`) goes through it.
Eigen::MatrixXd bind_checked(const Binder& binder, const geometry::Mesh& mesh,
                             const geometry::Skeleton& skeleton, const std::string& what);

}  // namespace skinlab::binders

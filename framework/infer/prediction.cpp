#include "framework/infer/prediction.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "framework/core/error.hpp"
#include "framework/core/timing.hpp"
#include "framework/data/source.hpp"
#include "framework/infer/map_back.hpp"

namespace skinlab::infer {

using Clock = std::chrono::steady_clock;

void check_predictable(const geometry::Character& c, const PredictOptions& options) {
  const int nv = c.mesh.num_vertices();
  if (nv > options.max_vertices) {
    throw Error(fmt::format("{}: {} vertices, more than the limit of {} (max_vertices; the "
                            "network's memory grows with #V: decimate the mesh, or raise the "
                            "limit with --max-vertices)",
                            c.name, nv, options.max_vertices));
  }
  if (nv == 0) throw Error(c.name + ": mesh has no vertices");
  const Eigen::RowVector3d lo = c.mesh.V.colwise().minCoeff(), hi = c.mesh.V.colwise().maxCoeff();
  const double diagonal = (hi - lo).norm();
  const auto& s = c.skeleton;
  for (int j = 0; j < s.num_joints(); ++j) {
    const Eigen::RowVector3d p = s.positions.row(j);
    const Eigen::RowVector3d outside = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
    if (outside.norm() > options.max_joint_outside * diagonal) {
      throw Error(fmt::format(
          "{}: joint '{}' at ({:.4g}, {:.4g}, {:.4g}) lies {:.4g} outside the mesh's bounding "
          "box [({:.4g}, {:.4g}, {:.4g}), ({:.4g}, {:.4g}, {:.4g})], more than {} of its "
          "diagonal: the rig does not fit this mesh (units or frame?)",
          c.name, s.names[j], p.x(), p.y(), p.z(), outside.norm(), lo.x(), lo.y(), lo.z(),
          hi.x(), hi.y(), hi.z(), options.max_joint_outside));
    }
  }
  if (s.num_joints() >= 2) {
    const Eigen::RowVector3d first = s.positions.row(0);
    double spread = 0;
    for (int j = 1; j < s.num_joints(); ++j) {
      spread = std::max(spread, (Eigen::RowVector3d(s.positions.row(j)) - first).norm());
    }
    if (!(spread > 1e-9 * std::max(diagonal, 1e-30))) {
      throw Error(fmt::format("{}: all {} joints sit at one point ({:.4g}, {:.4g}, {:.4g}), so "
                              "every bone has zero length and none gives a direction to skin "
                              "along",
                              c.name, s.num_joints(), first.x(), first.y(), first.z()));
    }
  }
}

data::PreparedCharacter prepare_to_predict(const geometry::Character& character,
                                           const Preparation& preparation,
                                           const PredictOptions& options, StageTimes* times) {
  if (!(options.prune >= 0 && options.prune <= 1)) {
    throw Error(fmt::format("prune must be in [0, 1], got {}", options.prune));
  }
  check_predictable(character, options);
  datasets::SourceCharacter source;
  source.character = character;
  source.path = character.name;
  source.up = options.up;
  data::PreprocessMode mode;
  mode.require_weights = false;
  mode.laplacian = false;
  data::PreprocessTimes pre;
  // The prediction does not depend on the input's weights: no weightless end joints are dropped
  // (which ones are weightless is the input weights' word), so the prediction covers every joint
  // of the input's skeleton, as the files it is written to do.
  data::PreprocessOptions preprocess = preparation.preprocess;
  preprocess.drop_weightless_leaves = 0;
  data::PreparedCharacter prepared =
      data::preprocess(source, preparation.distances, preprocess, mode, &pre);
  if (times != nullptr) {
    times->normalise += pre.normalise;
    times->distance += pre.distance;
    times->graph += pre.graph;
  }
  const std::string& distance = preparation.distance();
  const data::DistanceData& d = prepared.distances.at(distance);
  for (Eigen::Index v = 0; v < d.topk_distance.rows(); ++v) {
    for (Eigen::Index k = 0; k < d.topk_distance.cols(); ++k) {
      if (!std::isfinite(d.topk_distance(v, k))) {
        throw Error(fmt::format("{}: vertex {} (of the prepared mesh) has no finite {} distance "
                                "to candidate bone {}; cannot predict its weights",
                                character.name, v, distance, d.topk_index(v, k)));
      }
    }
  }
  return prepared;
}

Prediction finish_prediction(data::PreparedCharacter prepared, const std::string& distance,
                             data::RowMatrixXf candidates, double prune, StageTimes* times) {
  auto start = Clock::now();
  const data::DistanceData& d = prepared.distances.at(distance);
  const std::string& name = prepared.name;
  if (candidates.rows() != d.topk_index.rows() || candidates.cols() != d.topk_index.cols()) {
    throw Error(fmt::format("{}: the network returned {}×{} weights; expected #V×K = {}×{}, a "
                            "distribution over the {} candidates",
                            name, candidates.rows(), candidates.cols(), d.topk_index.rows(),
                            d.topk_index.cols(), distance));
  }
  // The distribution over the K candidates as #V×#B bone weights, pruned (Sec. 4.5).
  data::RowMatrixXd W = data::RowMatrixXd::Zero(candidates.rows(), prepared.num_bones());
  for (Eigen::Index v = 0; v < candidates.rows(); ++v) {
    for (Eigen::Index k = 0; k < candidates.cols(); ++k) {
      const float w = candidates(v, k);
      if (!(std::isfinite(w) && w >= 0)) {
        throw Error(fmt::format("{}: the network gave vertex {} (of the prepared mesh) the "
                                "weight {} for candidate {}",
                                name, v, w, k));
      }
      W(v, d.topk_index(v, k)) = w;
    }
  }
  prune_rows(W, prune);
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    if (!(W.row(v).sum() > 0)) {
      throw Error(fmt::format("{}: the network gave vertex {} (of the prepared mesh) no weight",
                              name, v));
    }
  }
  Prediction out;
  out.candidates = std::move(candidates);
  out.prepared_weights = W.cast<float>();
  if (prepared.weights.rows() > 0 || prepared.weights.cols() > 0) {
    // The truth by the preprocessing's own bone-level rule, from D as stored (float32).
    out.prepared_truth =
        data::bone_weights(prepared.weights, prepared.rig(), d.D.cast<double>()).cast<float>();
  }
  if (times != nullptr) times->network += seconds_since(start);

  start = Clock::now();
  out.source_weights = to_source_vertices(out.prepared_weights, prepared.vertex_map);
  out.joint_weights = joint_weights_of(out.source_weights, prepared.bones, prepared.num_joints());
  out.prepared = std::move(prepared);
  if (times != nullptr) times->map_back += seconds_since(start);
  return out;
}

}  // namespace skinlab::infer

#include "framework/infer/prediction.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "framework/core/error.hpp"
#include "framework/core/timing.hpp"
#include "framework/data/source.hpp"
#include "framework/geometry/weightless_leaves.hpp"
#include "framework/infer/map_back.hpp"

namespace skinlab::infer {

using Clock = std::chrono::steady_clock;

namespace {

/// #V×#J_kept joint weights as #V×#J_input: column k becomes column input_joints[k].
geometry::SparseWeights onto_input_joints(const geometry::SparseWeights& W,
                                          const std::vector<int>& input_joints,
                                          int num_input_joints) {
  if (static_cast<int>(input_joints.size()) == num_input_joints) return W;
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index v = 0; v < W.outerSize(); ++v) {
    for (geometry::SparseWeights::InnerIterator it(W, v); it; ++it) {
      entries.emplace_back(static_cast<int>(v), input_joints[static_cast<std::size_t>(it.col())],
                           it.value());
    }
  }
  geometry::SparseWeights out(W.rows(), num_input_joints);
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

/// `character`'s prior `prior` (#V×#B), checked to be as large as `W`; Error naming the
/// character and `what` (the option that needs it) otherwise.
const data::RowMatrixXf& prior_like(const data::RowMatrixXd& W,
                                    const data::PreparedCharacter& character,
                                    const std::string& prior, const char* what) {
  const auto it = character.priors.find(prior);
  if (it == character.priors.end()) {
    throw Error(fmt::format("{}: {} needs the '{}' prior, which the character was not prepared "
                            "with (preprocess.priors: [{{type: {}}}])",
                            character.name, what, prior, prior));
  }
  const data::RowMatrixXf& P = it->second;
  if (P.rows() != W.rows() || P.cols() != W.cols()) {
    throw Error(fmt::format("{}: the '{}' prior is {}×{}, the bone weights {}×{}", character.name,
                            prior, P.rows(), P.cols(), W.rows(), W.cols()));
  }
  return P;
}

}  // namespace

std::vector<int> check_predictable(const geometry::Character& c, const PredictOptions& options) {
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
  const int nj = s.num_joints();
  auto outside_by = [&](int j) {
    const Eigen::RowVector3d p = s.positions.row(j);
    return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).norm();
  };
  std::vector<bool> outside(static_cast<std::size_t>(nj), false);
  int first_outside = -1;
  for (int j = 0; j < nj; ++j) {
    outside[static_cast<std::size_t>(j)] = outside_by(j) > options.max_joint_outside * diagonal;
    if (outside[static_cast<std::size_t>(j)] && first_outside < 0) first_outside = j;
  }
  auto does_not_fit = [&](int j, const std::string& why) {
    const Eigen::RowVector3d p = s.positions.row(j);
    return Error(fmt::format(
        "{}: joint '{}' at ({:.4g}, {:.4g}, {:.4g}) lies {:.4g} outside the mesh's bounding "
        "box [({:.4g}, {:.4g}, {:.4g}), ({:.4g}, {:.4g}, {:.4g})], more than {} of its "
        "diagonal{}: the rig does not fit this mesh (units or frame?)",
        c.name, s.names[j], p.x(), p.y(), p.z(), outside_by(j), lo.x(), lo.y(), lo.z(), hi.x(),
        hi.y(), hi.z(), options.max_joint_outside, why));
  };
  std::vector<int> left_out;
  if (first_outside >= 0) {
    // The ends of the skeleton that lie wholly outside: what drop_leaves would remove.
    geometry::Character ends;
    ends.skeleton = s;
    const std::vector<int> kept = geometry::drop_leaves(
        ends, [&](int j) { return outside[static_cast<std::size_t>(j)]; });
    std::vector<bool> is_kept(static_cast<std::size_t>(nj), false);
    for (int j : kept) is_kept[static_cast<std::size_t>(j)] = true;
    for (int j = 0; j < nj; ++j) {
      if (!is_kept[static_cast<std::size_t>(j)]) {
        left_out.push_back(j);
      } else if (outside[static_cast<std::size_t>(j)]) {
        throw does_not_fit(j, "");  // a joint with a part of the skeleton inside below it
      }
    }
    if (2 * left_out.size() > static_cast<std::size_t>(nj)) {
      throw does_not_fit(first_outside, fmt::format(" (with {} of the {} joints)",
                                                    left_out.size(), nj));
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
  return left_out;
}

std::vector<int> without_helper_ends(geometry::Character& character,
                                     const std::vector<int>& left_out) {
  std::vector<bool> leave(static_cast<std::size_t>(character.skeleton.num_joints()), false);
  for (int j : left_out) leave[static_cast<std::size_t>(j)] = true;
  return geometry::drop_leaves(character,
                               [&](int j) { return leave[static_cast<std::size_t>(j)]; });
}

PreparedInput prepare_to_predict(const geometry::Character& character,
                                 const Preparation& preparation, const PredictOptions& options,
                                 StageTimes* times) {
  if (!(options.prune >= 0 && options.prune <= 1)) {
    throw Error(fmt::format("prune must be in [0, 1], got {}", options.prune));
  }
  PreparedInput input;
  input.left_out = check_predictable(character, options);
  input.num_input_joints = character.skeleton.num_joints();
  datasets::SourceCharacter source;
  source.character = character;
  input.input_joints = without_helper_ends(source.character, input.left_out);
  if (!input.left_out.empty()) {
    std::string names;
    for (int j : input.left_out) {
      names += (names.empty() ? "'" : ", '") + character.skeleton.names[j] + "'";
    }
    spdlog::warn("{}: {} outside the mesh at the end of the skeleton, left out of the "
                 "prediction with weight 0 (an IK target or a controller skins nothing)",
                 character.name, names);
  }
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
  input.prepared = data::preprocess(source, preparation.distances, preprocess, mode, &pre);
  const data::PreparedCharacter& prepared = input.prepared;
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
  return input;
}

void keep_prior_outside(data::RowMatrixXd& W, const data::PreparedCharacter& character,
                        const std::string& distance, const std::string& prior) {
  const data::RowMatrixXf& P = prior_like(W, character, prior, "keep_prior_outside");
  const data::RowMatrixXi& topk = character.distances.at(distance).topk_index;
  if (topk.rows() != W.rows()) {
    throw Error(fmt::format("{}: {} candidates for {} vertices of bone weights", character.name,
                            topk.rows(), W.rows()));
  }
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    double mass = 0;  // m_v: the prior's weight on v's candidates
    for (Eigen::Index k = 0; k < topk.cols(); ++k) mass += P(v, topk(v, k));
    Eigen::RowVectorXd row = P.row(v).cast<double>();
    for (Eigen::Index k = 0; k < topk.cols(); ++k) {
      const Eigen::Index b = topk(v, k);
      row(b) = mass * W(v, b);
    }
    W.row(v) = row;
  }
}

void mix_prior(data::RowMatrixXd& W, const data::PreparedCharacter& character,
               const std::string& prior, double alpha) {
  if (!(alpha >= 0 && alpha <= 1)) {
    throw Error(fmt::format("{}: prior_mix must be in [0, 1], got {}", character.name, alpha));
  }
  const data::RowMatrixXf& P = prior_like(W, character, prior, "prior_mix");
  W = (1 - alpha) * W + alpha * P.cast<double>();
}

void use_prior(data::RowMatrixXd& W, const data::PreparedCharacter& character,
               const std::string& distance, const PriorUse& use) {
  if (!use.acts()) return;
  if (use.keep_outside) keep_prior_outside(W, character, distance, use.prior);
  if (use.mix > 0) mix_prior(W, character, use.prior, use.mix);
}

Prediction finish_prediction(PreparedInput input, const std::string& distance,
                             data::RowMatrixXf candidates, double prune,
                             const PriorUse& prior, StageTimes* times) {
  const auto start = Clock::now();
  const data::PreparedCharacter& prepared = input.prepared;
  const data::DistanceData& d = prepared.distances.at(distance);
  const std::string& name = prepared.name;
  if (candidates.rows() != d.topk_index.rows() || candidates.cols() != d.topk_index.cols()) {
    throw Error(fmt::format("{}: the network returned {}×{} weights; expected #V×K = {}×{}, a "
                            "distribution over the {} candidates",
                            name, candidates.rows(), candidates.cols(), d.topk_index.rows(),
                            d.topk_index.cols(), distance));
  }
  // The distribution over the K candidates as #V×#B bone weights.
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
  use_prior(W, prepared, distance, prior);
  if (times != nullptr) times->network += seconds_since(start);
  Prediction out = finish_bone_weights(std::move(input), distance, std::move(W), prune,
                                       "the network", times);
  out.candidates = std::move(candidates);
  return out;
}

Prediction finish_bone_weights(PreparedInput input, const std::string& distance,
                               data::RowMatrixXd W, double prune, const std::string& method,
                               StageTimes* times) {
  auto start = Clock::now();
  data::PreparedCharacter& prepared = input.prepared;
  const data::DistanceData& d = prepared.distances.at(distance);
  const std::string& name = prepared.name;
  if (W.rows() != prepared.num_vertices() || W.cols() != prepared.num_bones()) {
    throw Error(fmt::format("{}: {} gave {}×{} bone weights; expected #V×#B = {}×{}", name, method,
                            W.rows(), W.cols(), prepared.num_vertices(), prepared.num_bones()));
  }
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    for (Eigen::Index b = 0; b < W.cols(); ++b) {
      if (!(std::isfinite(W(v, b)) && W(v, b) >= 0)) {
        throw Error(fmt::format("{}: {} gave vertex {} (of the prepared mesh) the weight {} for "
                                "bone {}",
                                name, method, v, W(v, b), b));
      }
    }
  }
  prune_rows(W, prune);  // Sec. 4.5
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    if (!(W.row(v).sum() > 0)) {
      throw Error(fmt::format("{}: {} gave vertex {} (of the prepared mesh) no weight", name,
                              method, v));
    }
  }
  Prediction out;
  out.prepared_weights = W.cast<float>();
  if (prepared.weights.rows() > 0 || prepared.weights.cols() > 0) {
    // The truth by the preprocessing's own bone-level rule, from D as stored (float32).
    out.prepared_truth =
        data::bone_weights(prepared.weights, prepared.rig(), d.D.cast<double>()).cast<float>();
  }
  if (times != nullptr) times->network += seconds_since(start);

  start = Clock::now();
  out.source_weights = to_source_vertices(out.prepared_weights, prepared.vertex_map);
  out.joint_weights = onto_input_joints(
      joint_weights_of(out.source_weights, prepared.bones, prepared.num_joints()),
      input.input_joints, input.num_input_joints);
  out.left_out_joints = std::move(input.left_out);
  out.input_joints = std::move(input.input_joints);
  out.prepared = std::move(prepared);
  if (times != nullptr) times->map_back += seconds_since(start);
  return out;
}

}  // namespace skinlab::infer

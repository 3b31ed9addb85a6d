#include "framework/predict/predictor.hpp"

#include <fmt/format.h>
#include <torch/torch.h>

#include <algorithm>
#include <cmath>

#include "framework/data/source.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/core/timing.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/h5.hpp"
#include "framework/tensors/tensors.hpp"
#include "framework/eval/evaluate.hpp"
#include "framework/eval/predictions.hpp"
#include "framework/eval/weights.hpp"
#include "framework/geometry/weightless_leaves.hpp"
#include "framework/models/model.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::predict {

namespace fs = std::filesystem;

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

std::string read_preparation(const fs::path& dir, const train::RunOptions& run) {
  const fs::path own = dir / "preparation.yaml";
  if (fs::exists(own)) return read_file(own);
  if (run.data.file.empty()) {
    throw IoError(dir.string() + ": no preparation.yaml and no data.file in config.yaml");
  }
  const fs::path data = run.data.file;
  if (!fs::exists(data)) {
    throw IoError(dir.string() + ": no preparation.yaml, and the run's dataset " + data.string() +
                  " (data.file), whose preprocessing the model needs, does not exist; prepare "
                  "it again or predict with a bundled model (skinlab bundle)");
  }
  const data::H5Reader reader(data);
  if (!reader.has_attribute("/", "preparation")) {
    throw IoError(data.string() + ": no 'preparation' attribute (written by skinlab prepare)");
  }
  return reader.read_attribute("/", "preparation");
}

Predictor Predictor::load(const fs::path& dir, const std::string& checkpoint) {
  const fs::path config_file = dir / "config.yaml";
  if (!fs::is_directory(dir) || !fs::exists(config_file)) {
    throw IoError(dir.string() + ": not a model directory (no config.yaml); give a run directory "
                  "of skinlab train or a bundled model (results/bundled/<name>)");
  }
  const config::Config config = config::Config::load(config_file);
  Predictor p;
  p.options_ = train::RunOptions::from(config);
  if (!p.options_.model.exists()) {
    throw ConfigError(config_file.string() +
                      ": no model section; skinlab predict needs a trained model");
  }
  const fs::path bundled = dir / "model.pt";
  fs::path weights;
  if (fs::exists(bundled)) {
    weights = bundled;
  } else {
    weights = train::checkpoint_file(dir, checkpoint);
    if (!fs::exists(weights)) {
      throw IoError(weights.string() + ": no checkpoint (checkpoints stay out of git; train the "
                    "run again or use the bundled model)");
    }
  }

  const std::string preparation_yaml = read_preparation(dir, p.options_);
  const config::Config preparation =
      config::Config::parse(preparation_yaml, (dir / "preparation.yaml").string());
  p.preprocess_ = data::PreprocessOptions::from(preparation.root()["preprocess"]);
  const config::Node distances = preparation.root()["distances"];
  for (std::size_t i = 0; i < distances.size(); ++i) {
    const config::Node node = distances[i];
    if (node.required_type("distance") != p.options_.data.distance) continue;
    p.distances_.push_back({p.options_.data.distance, distance_registry().create(node)});
  }
  if (p.distances_.empty()) {
    throw ConfigError(dir.string() + ": the model reads distance '" + p.options_.data.distance +
                      "', which its preparation does not list");
  }

  p.model_ = train::build_model(p.options_);
  const train::TrainingState state = train::load_checkpoint(weights, *p.model_);
  p.model_->eval();
  if (p.options_.metrics.exists() && p.options_.metrics.size() > 0) {
    p.metrics_ = eval::make_metrics(p.options_.metrics);
  }
  p.description_ = fmt::format("{} ({}, epoch {})", dir.string(), weights.filename().string(),
                               state.epoch);
  return p;
}

Prediction Predictor::predict(const geometry::Character& character, const PredictOptions& options,
                              StageTimes* times) const {
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
  Prediction out;
  // The prediction does not depend on the input's weights: no weightless end joints are dropped
  // (which ones are weightless is the input weights' word), so the prediction covers every joint
  // of the input's skeleton, as the files it is written to do.
  data::PreprocessOptions preprocess = preprocess_;
  preprocess.drop_weightless_leaves = 0;
  out.prepared = data::preprocess(source, distances_, preprocess, mode, &pre);
  if (times != nullptr) {
    times->normalise += pre.normalise;
    times->distance += pre.distance;
    times->graph += pre.graph;
  }

  auto start = Clock::now();
  const data::DistanceData& d = out.prepared.distances.at(distance());
  for (Eigen::Index v = 0; v < d.topk_distance.rows(); ++v) {
    for (Eigen::Index k = 0; k < d.topk_distance.cols(); ++k) {
      if (!std::isfinite(d.topk_distance(v, k))) {
        throw Error(fmt::format("{}: vertex {} (of the prepared mesh) has no finite {} distance "
                                "to candidate bone {}; cannot predict its weights",
                                character.name, v, distance(), d.topk_index(v, k)));
      }
    }
  }
  const data::CharacterTensors c = data::to_tensors(out.prepared, distance());
  torch::Tensor candidates;
  {
    torch::NoGradGuard no_grad;
    candidates = model_->forward(c);
  }
  train::check_prediction(candidates, c, options_);
  const torch::Tensor scattered = data::scatter_to_bones(candidates, c.topk_index, c.num_bones());
  data::RowMatrixXd W = eval::to_eigen(scattered).cast<double>();
  eval::prune_rows(W, options.prune);
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    if (!(W.row(v).sum() > 0)) {
      throw Error(fmt::format("{}: the network gave vertex {} (of the prepared mesh) no weight",
                              character.name, v));
    }
  }
  out.candidates = eval::to_eigen(candidates);
  out.prepared_weights = W.cast<float>();
  if (c.bone_weights.defined()) out.prepared_truth = eval::to_eigen(c.bone_weights);
  if (times != nullptr) times->network += seconds_since(start);

  start = Clock::now();
  out.source_weights = eval::to_source_vertices(out.prepared_weights, out.prepared.vertex_map);
  out.joint_weights =
      eval::joint_weights_of(out.source_weights, out.prepared.bones, out.prepared.num_joints());
  if (times != nullptr) times->map_back += seconds_since(start);
  return out;
}

std::map<std::string, double> Predictor::metrics_of(const torch::Tensor& pred,
                                                    const torch::Tensor& target,
                                                    const data::PreparedCharacter& character) const {
  eval::MetricInputs in;
  in.pred = pred;
  in.target = target;
  in.character = &character;
  std::map<std::string, double> values;
  for (const auto& metric : metrics_) {
    for (const auto& [name, value] : (*metric)(in)) values[name] = value;
  }
  return values;
}

std::map<std::string, double> Predictor::compare(const Prediction& p) const {
  if (p.prepared_truth.rows() == 0) {
    throw Error(p.prepared.name + ": the input carries no skin weights to compare with");
  }
  auto tensor = [](const data::RowMatrixXf& m) {
    return torch::from_blob(const_cast<float*>(m.data()), {m.rows(), m.cols()}, torch::kFloat32);
  };
  return metrics_of(tensor(p.prepared_weights), tensor(p.prepared_truth), p.prepared);
}

std::map<std::string, double> Predictor::score(const geometry::Character& truth,
                                               const geometry::SparseWeights& other,
                                               const PredictOptions& options) const {
  if (!truth.has_weights()) throw Error(truth.name + ": no weights to score against");
  if (other.rows() != truth.mesh.num_vertices() || other.cols() != truth.skeleton.num_joints()) {
    throw Error(fmt::format("{}: the weights to score are {}×{}, expected #V×#J = {}×{}",
                            truth.name, other.rows(), other.cols(), truth.mesh.num_vertices(),
                            truth.skeleton.num_joints()));
  }
  check_predictable(truth, options);
  data::PreprocessMode mode;
  mode.laplacian = false;
  // The truth decides where the skeleton ends: when the preparation drops its weightless end
  // joints (preprocess's drop_weightless_leaves), the other weights are moved onto the same kept
  // joints, a dropped joint's weight to its nearest kept ancestor (it lies on that ancestor's
  // bone), and both are prepared without dropping, on the same bones. Otherwise a method that
  // weights end joints (Blender does) would be prepared with more bones than the truth.
  geometry::Character base = truth;
  geometry::SparseWeights others = other;
  data::PreprocessOptions preprocess = preprocess_;
  if (data::drops_weightless_leaves(preprocess_, truth.name)) {
    const std::vector<int> kept = geometry::drop_weightless_leaves(base);
    others = geometry::onto_kept_joints(other, truth.skeleton.parents, kept);
    preprocess.drop_weightless_leaves = 0;
  }
  auto prepare = [&](const geometry::SparseWeights& W) {
    datasets::SourceCharacter source;
    source.character = base;
    source.character.weights = W;
    source.path = truth.name;
    source.up = options.up;
    return data::preprocess(source, distances_, preprocess, mode);
  };
  const data::PreparedCharacter t = prepare(base.weights);
  const data::PreparedCharacter o = prepare(others);
  return metrics_of(data::to_tensors(o, distance()).bone_weights,
                    data::to_tensors(t, distance()).bone_weights, t);
}

void bundle(const fs::path& run_dir, const fs::path& out, const std::string& checkpoint) {
  if (fs::exists(out)) throw IoError(out.string() + ": exists; remove it or choose another --out");
  const fs::path config_file = run_dir / "config.yaml";
  const fs::path weights = train::checkpoint_file(run_dir, checkpoint);
  for (const fs::path& f : {config_file, weights}) {
    if (!fs::exists(f)) throw IoError(f.string() + ": missing; bundle needs a trained run");
  }
  const train::RunOptions options = train::RunOptions::from(config::Config::load(config_file));
  if (!options.model.exists()) throw ConfigError(config_file.string() + ": no model section");
  const std::string preparation = read_preparation(run_dir, options);

  const std::shared_ptr<models::Model> model = train::build_model(options);
  const train::TrainingState state = train::load_checkpoint(weights, *model);

  write_directory_atomic(out, [&](const fs::path& staging) {
    fs::copy_file(config_file, staging / "config.yaml");
    write_file_atomic(staging / "preparation.yaml", preparation);
    train::TrainingState kept = state;  // without the RNG states: nothing resumes a bundle
    kept.torch_rng = torch::Tensor();
    kept.order_rng = torch::Tensor();
    train::save_checkpoint(staging / "model.pt", *model, nullptr, kept);
    for (const auto& entry : fs::directory_iterator(run_dir)) {
      const std::string name = entry.path().filename().string();
      const bool provenance = name == "env.json" || name == "metrics.jsonl" ||
                              (name.rfind("eval_", 0) == 0 &&
                               (entry.path().extension() == ".json" ||
                                entry.path().extension() == ".csv"));
      if (provenance) fs::copy_file(entry.path(), staging / name);
    }
    write_file_atomic(staging / "source.txt",
                      fmt::format("run: {}\ncheckpoint: {}.pt\nepoch: {}\n", run_dir.string(),
                                  checkpoint, state.epoch));
  });
}

}  // namespace skinlab::predict

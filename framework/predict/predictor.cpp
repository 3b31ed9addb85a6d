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
#include "framework/infer/model_dir.hpp"
#include "framework/geometry/weightless_leaves.hpp"
#include "framework/models/branched_model.hpp"
#include "framework/models/model.hpp"
#include "framework/predict/parameter_export.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::predict {

namespace fs = std::filesystem;

using Clock = std::chrono::steady_clock;

Predictor Predictor::load(const fs::path& dir, const std::string& checkpoint) {
  const fs::path config_file = infer::model_config_file(
      dir, "give a run directory of skinlab train or a bundled model (results/bundled/<name>)");
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

  const models::PriorOptions prior = models::PriorOptions::of(p.options_.model);
  p.preparation_ = infer::load_preparation(dir, p.options_.data.file, p.options_.data.distance,
                                           prior.prior);
  p.prior_use_ = {prior.prior, prior.keep_prior_outside, prior.prior_mix};

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
  infer::PreparedInput input = infer::prepare_to_predict(character, preparation_, options, times);
  const auto start = Clock::now();
  const data::CharacterTensors c = data::to_tensors(input.prepared, distance());
  torch::Tensor candidates;
  {
    torch::NoGradGuard no_grad;
    candidates = model_->forward(c);
  }
  train::check_prediction(candidates, c, options_);
  data::RowMatrixXf output = eval::to_eigen(candidates);
  if (times != nullptr) times->network += seconds_since(start);
  return infer::finish_prediction(std::move(input), distance(), std::move(output), options.prune,
                                  prior_use_, times);
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
  data::PreprocessMode mode;
  mode.laplacian = false;
  // Both are scored on the skeleton a prediction skins: without the helper ends outside the
  // mesh (IK targets, controllers; check_predictable), a left-out joint's weight, if any, on its
  // nearest kept ancestor.
  geometry::Character base = truth;
  const std::vector<int> kept =
      infer::without_helper_ends(base, check_predictable(truth, options));
  geometry::SparseWeights others = geometry::onto_kept_joints(other, truth.skeleton.parents, kept);
  // The truth decides where the skeleton ends: when the preparation drops its weightless end
  // joints (preprocess's drop_weightless_leaves), the other weights are moved onto the same kept
  // joints, a dropped joint's weight to its nearest kept ancestor (it lies on that ancestor's
  // bone), and both are prepared without dropping, on the same bones. Otherwise a method that
  // weights end joints (Blender does) would be prepared with more bones than the truth.
  data::PreprocessOptions preprocess = preparation_.preprocess;
  if (data::drops_weightless_leaves(preparation_.preprocess, truth.name)) {
    const std::vector<int> parents = base.skeleton.parents;
    others = geometry::onto_kept_joints(others, parents, geometry::drop_weightless_leaves(base));
    preprocess.drop_weightless_leaves = 0;
  }
  auto prepare = [&](const geometry::SparseWeights& W) {
    datasets::SourceCharacter source;
    source.character = base;
    source.character.weights = W;
    source.path = truth.name;
    source.up = options.up;
    return data::preprocess(source, preparation_.distances, preprocess, mode);
  };
  const data::PreparedCharacter t = prepare(base.weights);
  const data::PreparedCharacter o = prepare(others);
  return metrics_of(data::to_tensors(o, distance()).bone_weights,
                    data::to_tensors(t, distance()).bone_weights, t);
}

void Predictor::write_parameters(const fs::path& file) const {
  write_parameter_file(file, *model_, options_, description_);
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
  const std::string preparation = infer::read_preparation(run_dir, options.data.file);

  const std::shared_ptr<models::Model> model = train::build_model(options);
  const train::TrainingState state = train::load_checkpoint(weights, *model);

  write_directory_atomic(out, [&](const fs::path& staging) {
    fs::copy_file(config_file, staging / "config.yaml");
    write_file_atomic(staging / "preparation.yaml", preparation);
    train::TrainingState kept = state;  // without the RNG states: nothing resumes a bundle
    kept.torch_rng = torch::Tensor();
    kept.order_rng = torch::Tensor();
    train::save_checkpoint(staging / "model.pt", *model, nullptr, kept);
    write_parameter_file(staging / "parameters.h5", *model, options,
                         fmt::format("{} ({}.pt, epoch {})", run_dir.string(), checkpoint,
                                     state.epoch));
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

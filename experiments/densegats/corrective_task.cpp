#include "experiments/densegats/corrective_task.hpp"

#include <ATen/CPUGeneratorImpl.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>

#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/progress.hpp"
#include "framework/core/registry.hpp"
#include "framework/core/timing.hpp"
#include "framework/data/h5.hpp"
#include "framework/geometry/dqs.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/fit_support.hpp"
#include "framework/eval/value_display.hpp"

namespace skinlab::densegats {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

std::int64_t draw(at::Generator& rng, std::int64_t n) {
  return torch::randint(n, {1}, rng, torch::TensorOptions().dtype(torch::kInt64)).item<std::int64_t>();
}

void set_lr(torch::optim::Adam& optimizer, double lr) {
  for (auto& group : optimizer.param_groups()) {
    static_cast<torch::optim::AdamOptions&>(group.options()).lr(lr);
  }
}

std::shared_ptr<models::CorrectiveModel> build(const CorrectiveConfig& c, const CorrectiveData& data) {
  torch::manual_seed(static_cast<std::uint64_t>(c.run.seed));
  auto model = corrective_model_registry().create(c.run.model);
  if (model->input_width() != data.feature_width()) {
    c.run.model.fail(fmt::format(
        "the model is built for {} node attributes, but the data's are 6 + {} joints = {} wide "
        "(set model.input_width: {})",
        model->input_width(), data.num_joints(), data.feature_width(), data.feature_width()));
  }
  return model;
}

std::unique_ptr<CorrectiveData> make_data(const train::RunData& run_data, const CorrectiveConfig& c) {
  return std::make_unique<CorrectiveData>(run_data.dataset(), c.run.data.file, c.corrective);
}

}  // namespace

graph::Graph mesh_graph(const CorrectiveCharacter& character) {
  graph::Graph g;
  g.one_ring = character.one_ring;
  g.num_vertices = character.num_vertices();
  return g;
}

std::vector<int> evenly_spaced(std::size_t n, int count) {
  std::vector<int> out;
  if (n <= static_cast<std::size_t>(count)) {
    for (std::size_t p = 0; p < n; ++p) out.push_back(static_cast<int>(p));
    return out;
  }
  for (int k = 0; k < count; ++k) out.push_back(static_cast<int>(k * n / static_cast<std::size_t>(count)));
  return out;
}

std::vector<int> eval_pose_indices(const CorrectiveCharacter& character, int count) {
  return evenly_spaced(character.poses.size(), count);
}

Window window_of(const CorrectiveSample& sample, const torch::Tensor& one_ring,
                 std::int64_t first, std::int64_t count) {
  const std::int64_t end = first + count;
  const torch::Tensor i = one_ring.select(1, 0), j = one_ring.select(1, 1);
  const torch::Tensor inside = (i >= first) & (i < end) & (j >= first) & (j < end);
  Window w;
  w.features = sample.features.narrow(0, first, count);
  w.target = sample.displacement_t.narrow(0, first, count);
  w.graph.one_ring = one_ring.index({inside}) - first;
  w.graph.num_vertices = count;
  return w;
}

CorrectiveConfig CorrectiveConfig::from(const config::Config& config) {
  CorrectiveConfig c;
  c.run = train::RunOptions::from(config);
  if (c.run.task != "corrective") {
    throw ConfigError(config.source() + ": task is '" + c.run.task +
                      "'; the corrective-deformation task needs `task: corrective`");
  }
  c.corrective = CorrectiveOptions::from(c.run.task_section);
  if (!c.corrective.baseline.empty() && c.run.model.exists()) {
    c.run.model.fail("a corrective config has a 'model' to train or a 'corrective.baseline' "
                     "deformer to evaluate, not both");
  }
  return c;
}

CorrectiveTrainer::CorrectiveTrainer(const config::Config& config)
    : config_(config), options_(CorrectiveConfig::from(config)), run_data_([&] {
        if (!options_.corrective.baseline.empty()) {
          throw ConfigError(config.source() + ": corrective.baseline '" +
                            options_.corrective.baseline + "' is not trained; evaluate it with "
                            "`skinlab eval " + config.source() + " --split test`");
        }
        options_.run.require_training_sections(config);
        return train::RunData(options_.run.data);
      }()) {
  data_ = make_data(run_data_, options_);
  train_ = data_->members(run_data_.part("train"));
  val_ = data_->members(run_data_.part("val"));
  if (train_.empty()) {
    throw IoError(options_.run.data.file + ": split '" + options_.run.data.split +
                  "' has no training character of skeleton family '" +
                  options_.corrective.skeleton + "' with clips");
  }
  for (int c : val_) {
    const CorrectiveCharacter& ch = data_->characters()[static_cast<std::size_t>(c)];
    for (int p : eval_pose_indices(ch, options_.corrective.eval_poses)) {
      const CorrectiveSample s = data_->sample(c, p);
      validation_.push_back({s.features, s.displacement_t, mesh_graph(ch)});
    }
  }
  model_ = build(options_, *data_);
  train::check_checkpointable(*model_);
  initial_torch_rng_ = train::get_rng_state(at::detail::getDefaultCPUGenerator());
  loss_ = losses::LossSum::from(options_.run.losses);
  const auto parameters = model_->parameters();
  if (parameters.empty()) options_.run.model.fail("the model has no trainable parameters");
  optimizer_ = std::make_unique<torch::optim::Adam>(
      parameters, torch::optim::AdamOptions(options_.run.train.lr)
                      .weight_decay(options_.run.train.weight_decay));
  spdlog::info("corrective task: {} train and {} val characters of '{}', {} poses each, {} "
               "clips; {} left out",
               train_.size(), val_.size(), options_.corrective.skeleton,
               data_->characters().front().poses.size(), data_->clips().size(),
               data_->excluded().size());
}

torch::Tensor CorrectiveTrainer::loss_tensor(const torch::Tensor& pred, const torch::Tensor& target,
                                             std::map<std::string, double>* parts) const {
  losses::LossInputs in;
  in.pred = pred;
  in.target = target;
  return loss_(in, parts);
}

double CorrectiveTrainer::loss_of(const torch::Tensor& pred, const torch::Tensor& target,
                                  std::map<std::string, double>* parts) const {
  return loss_tensor(pred, target, parts).item<double>();
}

double CorrectiveTrainer::validation_loss() {
  if (validation_.empty()) return std::nan("");
  const bool was_training = model_->is_training();
  model_->eval();
  torch::NoGradGuard no_grad;
  double total = 0;
  for (const Cached& v : validation_) total += loss_of(model_->forward(v.features, v.graph), v.target);
  model_->train(was_training);
  return total / static_cast<double>(validation_.size());
}

double CorrectiveTrainer::step(const std::vector<std::pair<int, int>>& batch, at::Generator& rng) {
  optimizer_->zero_grad();
  double total = 0;
  const std::int64_t window = options_.corrective.window;
  for (const auto& [c, pose] : batch) {
    const CorrectiveCharacter& ch = data_->characters()[static_cast<std::size_t>(c)];
    const CorrectiveSample s = data_->sample(c, pose);
    const std::int64_t n = ch.num_vertices();
    const std::int64_t count = window > 0 && window < n ? window : n;
    const std::int64_t first = count < n ? draw(rng, n - count + 1) : 0;
    const Window w = window_of(s, ch.one_ring, first, count);
    torch::Tensor loss = loss_tensor(model_->forward(w.features, w.graph), w.target, nullptr);
    const double value = loss.item<double>();
    if (!std::isfinite(value)) {
      throw Error(fmt::format("training loss is {} on character '{}' pose {}; lower train.lr?",
                              value, ch.name, pose));
    }
    (loss / static_cast<double>(batch.size())).backward();
    total += value;
  }
  optimizer_->step();
  return total / static_cast<double>(batch.size());
}

train::TrainResult CorrectiveTrainer::fit(const RunDir& run, const train::FitLimits& limits) {
  if (fitted_) throw Error("CorrectiveTrainer::fit: a trainer trains once; build a new one");
  fitted_ = true;
  const auto start = Clock::now();
  const train::TrainOptions& t = options_.run.train;
  const CorrectiveOptions& o = options_.corrective;
  train::TrainResult result;

  at::Generator torch_rng = at::detail::getDefaultCPUGenerator();
  at::Generator order_rng =
      at::make_generator<at::CPUGeneratorImpl>(train::order_seed(options_.run.seed));
  train::FitStart begun = train::start_fit(run, *model_, *optimizer_, options_.run.seed, t,
                                           options_.run.model.to_yaml(), torch_rng, order_rng,
                                           initial_torch_rng_);
  train::TrainingState& state = begun.state;
  result.resumed = begun.resumed;
  const fs::path last = run.file(train::kLastCheckpoint);
  double lr = t.lr, plateau_best = std::numeric_limits<double>::infinity();
  int plateau_bad = 0;
  if (begun.resumed) {
    const auto& extra = begun.extra;
    lr = extra.count("lr") ? extra.at("lr") : lr;
    plateau_best = extra.count("plateau_best") ? extra.at("plateau_best") : plateau_best;
    plateau_bad = extra.count("plateau_bad") ? static_cast<int>(extra.at("plateau_bad")) : 0;
    set_lr(*optimizer_, lr);
    spdlog::info("learning rate {:.3g} (plateau: best {:.6g}, {} bad epochs)", lr, plateau_best, plateau_bad);
  }
  const bool have_val = !validation_.empty();
  if (!have_val) spdlog::warn("no validation character: best.pt and early stopping use the train loss");

  model_->train();
  const auto session_start = Clock::now();
  while (!train::finished(state, t)) {
    const std::int64_t epoch = state.epoch + 1;
    const auto epoch_start = Clock::now();
    const std::string label = fmt::format("epoch {}/{}", epoch, t.epochs);
    std::vector<std::pair<int, int>> samples;
    for (int k = 0; k < o.samples_per_epoch; ++k) {
      const int c = train_[static_cast<std::size_t>(draw(order_rng, static_cast<std::int64_t>(train_.size())))];
      const auto poses = static_cast<std::int64_t>(data_->characters()[static_cast<std::size_t>(c)].poses.size());
      samples.emplace_back(c, static_cast<int>(draw(order_rng, poses)));
    }
    double train_sum = 0;
    std::size_t steps = 0;
    for (std::size_t b = 0; b < samples.size(); b += static_cast<std::size_t>(o.batch_size)) {
      const std::vector<std::pair<int, int>> batch(
          samples.begin() + static_cast<std::ptrdiff_t>(b),
          samples.begin() + static_cast<std::ptrdiff_t>(std::min(samples.size(), b + static_cast<std::size_t>(o.batch_size))));
      train_sum += step(batch, order_rng);
      ++steps;
      if (t.log_every > 0 && steps % static_cast<std::size_t>(t.log_every) == 0) {
        spdlog::info("{} loss {:.5g}",
                     Progress::format(label, b + batch.size(), samples.size(), seconds_since(epoch_start)),
                     train_sum / static_cast<double>(steps));
      }
    }
    const double train_loss = train_sum / static_cast<double>(steps);
    const double val_loss = have_val ? validation_loss() : std::nan("");
    const double selection = have_val ? val_loss : train_loss;
    const bool improved = train::record_epoch(state, epoch, selection, t.min_delta);
    // ReduceLROnPlateau (mode min, threshold 0): decay after more than `patience` bad epochs.
    const double used_lr = lr;
    if (selection < plateau_best) {
      plateau_best = selection;
      plateau_bad = 0;
    } else if (++plateau_bad > o.plateau_patience) {
      lr = std::max(lr * o.plateau_factor, o.plateau_min_lr);
      set_lr(*optimizer_, lr);
      plateau_bad = 0;
      spdlog::info("{}: no improvement for {} epochs, learning rate {:.3g} -> {:.3g}", label,
                   o.plateau_patience + 1, used_lr, lr);
    }
    state.extra = {{"lr", lr}, {"plateau_best", plateau_best}, {"plateau_bad", plateau_bad}};
    state.torch_rng = train::get_rng_state(torch_rng);
    state.order_rng = train::get_rng_state(order_rng);
    const double seconds = seconds_since(epoch_start);
    run.append_metrics({{"epoch", epoch},
                        {"train_loss", train_loss},
                        {"val_loss", have_val ? nlohmann::json(val_loss) : nlohmann::json()},
                        {"best_epoch", state.best_epoch},
                        {"best_loss", state.best_loss},
                        {"improved", improved},
                        {"samples", samples.size()},
                        {"lr", used_lr},
                        {"seconds", seconds}});
    if (improved) save_checkpoint(run.file(train::kBestCheckpoint), *model_, optimizer_.get(), state);
    save_checkpoint(last, *model_, optimizer_.get(), state);
    ++result.epochs_this_call;
    const double eta = seconds_since(session_start) / result.epochs_this_call *
                       static_cast<double>(t.epochs - epoch);
    spdlog::info("{}: train loss {:.5g}{} | lr {:.3g} | {:.1f} s, ETA {}{}", label, train_loss,
                 have_val ? fmt::format(", val loss {:.5g}", val_loss) : std::string(), used_lr,
                 seconds, train::duration(eta), improved ? " *best*" : "");
    if (limits.stop_after_epochs > 0 && result.epochs_this_call >= limits.stop_after_epochs &&
        state.epoch < t.epochs) {
      result.interrupted = true;
      break;
    }
  }
  train::finish_fit(result, state, t, start);
  return result;
}

eval::EvalReport evaluate_corrective(const RunDir& run, const eval::EvalOptions& options) {
  const auto start = Clock::now();
  const config::Config config = config::Config::load(run.file("config.yaml"), options.overrides);
  const CorrectiveConfig c = CorrectiveConfig::from(config);
  const std::string& baseline = c.corrective.baseline;
  fs::path checkpoint;
  if (baseline.empty()) {
    c.run.require_training_sections(config);
    checkpoint = train::existing_checkpoint(run.path(), options.checkpoint);
  } else if (!c.run.data_node.exists()) {
    throw ConfigError(config.source() + ": evaluating a config needs a 'data' section");
  }
  train::RunData run_data(c.run.data);
  const std::unique_ptr<CorrectiveData> data = make_data(run_data, c);
  const std::vector<int> members = data->members(run_data.part(options.part));
  if (members.empty()) {
    throw Error(c.run.data.file + ": part '" + options.part + "' of split '" + c.run.data.split +
                "' has no character of skeleton family '" + c.corrective.skeleton + "' with clips");
  }
  std::shared_ptr<models::CorrectiveModel> model;
  std::unique_ptr<losses::LossSum> loss;
  std::int64_t epoch = 0;
  if (baseline.empty()) {
    model = build(c, *data);
    epoch = train::load_checkpoint(checkpoint, *model).epoch;
    loss = std::make_unique<losses::LossSum>(losses::LossSum::from(c.run.losses));
    model->eval();
  }

  eval::EvalReport report;
  report.split = c.run.data.split;
  report.part = options.part;
  report.checkpoint = baseline.empty() ? options.checkpoint : "none";
  report.epoch = static_cast<int>(epoch);
  torch::NoGradGuard no_grad;
  std::unique_ptr<data::H5Writer> predictions;
  std::vector<std::string> predicted_names;
  if (options.predictions) {
    fs::create_directories(run.file("predictions"));
    predictions = std::make_unique<data::H5Writer>(run.file("predictions") / (options.part + ".h5"));
  }
  Progress progress("eval " + options.part, members.size());
  for (int index : members) {
    const CorrectiveCharacter& ch = data->characters()[static_cast<std::size_t>(index)];
    double sum = 0, most = 0, least = std::numeric_limits<double>::infinity(), loss_sum = 0;
    std::size_t count = 0;
    const std::vector<int> poses = eval_pose_indices(ch, c.corrective.eval_poses);
    const auto V = static_cast<Eigen::Index>(ch.num_vertices());
    data::RowMatrixXf corrections(predictions ? V * static_cast<Eigen::Index>(poses.size()) : 0, 3);
    data::RowMatrixXf errors(predictions ? static_cast<Eigen::Index>(poses.size()) : 0, V);
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const int pose = poses[k];
      const CorrectiveSample s = data->sample(index, pose);
      Eigen::MatrixXd correction = Eigen::MatrixXd::Zero(s.lbs.rows(), 3);  // lbs: none
      if (model) {
        const torch::Tensor pred = model->forward(s.features, mesh_graph(ch));
        losses::LossInputs in;
        in.pred = pred;
        in.target = s.displacement_t;
        loss_sum += (*loss)(in).item<double>();
        const auto a = pred.accessor<float, 2>();
        for (Eigen::Index i = 0; i < correction.rows(); ++i)
          for (int k = 0; k < 3; ++k) correction(i, k) = a[i][k];
      } else if (baseline == "dqs") {
        correction = (geometry::dqs(ch.mesh.V, ch.weights, s.transforms) - s.lbs) *
                     data->cm_per_unit();
      }
      const Eigen::VectorXd error = (correction - s.displacement).rowwise().norm();
      if (predictions) {
        corrections.middleRows(static_cast<Eigen::Index>(k) * V, V) = correction.cast<float>();
        errors.row(static_cast<Eigen::Index>(k)) = error.transpose().cast<float>();
      }
      sum += error.sum();
      most = std::max(most, error.maxCoeff());
      least = std::min(least, error.minCoeff());
      count += static_cast<std::size_t>(error.size());
    }
    eval::CharacterResult r;
    r.name = ch.name;
    r.vertices = ch.num_vertices();
    r.bones = ch.num_joints();
    r.values["mean_error_cm"] = sum / static_cast<double>(count);
    r.values["max_error_cm"] = most;
    r.values["min_error_cm"] = least;
    r.values["poses"] = static_cast<double>(poses.size());
    if (model) r.values["loss"] = loss_sum / static_cast<double>(poses.size());
    if (predictions) {
      const std::string group = "/characters/" + ch.name;
      predictions->create_group(group);
      predictions->write(group + "/poses", poses);
      predictions->write(group + "/correction_cm", corrections);
      predictions->write(group + "/error_cm", errors);
      predicted_names.push_back(ch.name);
    }
    report.characters.push_back(std::move(r));
    progress.tick();
  }
  progress.finish();
  report.mean = eval::mean_values(report.characters);
  if (predictions) {
    predictions->write_strings("/character_names", predicted_names);
    const std::pair<const char*, std::string> attributes[] = {
        {"task", "corrective"},
        {"experiment", c.run.experiment},
        {"run", run.id()},
        {"split", c.run.data.split},
        {"part", options.part},
        {"checkpoint", report.checkpoint},
        {"method", baseline.empty() ? std::string("model") : baseline}};
    for (const auto& [name, value] : attributes) predictions->write_attribute("/", name, value);
    predictions->write_attribute("/", "epoch", epoch);
    predictions->commit();
    report.predictions = predictions->target();
  }
  report.seconds = seconds_since(start);
  eval::write_eval_files(run, report,
                         {{"experiment", c.run.experiment},
                          {"run", run.id()},
                          {"task", "corrective"},
                          {"dataset", c.run.data.file},
                          {"split", c.run.data.split},
                          {"part", options.part},
                          {"method", baseline.empty() ? "model" : "baseline"},
                          {"type", baseline.empty() ? c.run.model["type"].as<std::string>() : baseline},
                          {"checkpoint", report.checkpoint},
                          {"epoch", epoch},
                          {"height_m", c.corrective.height_m},
                          {"metric_definitions",
                           fmt::format("a vertex's error is its distance to the Delta Mush "
                                       "target (Mancewicz et al. 2014, applied to the artist-"
                                       "weighted LBS mesh) in cm with the character scaled to "
                                       "{} m; per character, the mean, max and min over every "
                                       "vertex at {} evenly spaced poses of the pooled clips "
                                       "(frame stride {}) (DenseGATs Sec. 4.2, Table 3)",
                                       c.corrective.height_m, c.corrective.eval_poses,
                                       c.corrective.frame_stride)},
                          {"skeleton", c.corrective.skeleton}});
  return report;
}

}  // namespace skinlab::densegats

// DenseGATs Table 3's values: vertex error over the evaluation poses, in cm.
SKINLAB_DECLARE_VALUE({"mean_error_cm", "Mean err.", "cm", false, false, 4});
SKINLAB_DECLARE_VALUE({"max_error_cm", "Max err.", "cm", false, false, 4});
SKINLAB_DECLARE_VALUE({"min_error_cm", "Min err.", "cm", false, false, 4});

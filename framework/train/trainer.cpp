#include "framework/train/trainer.hpp"

#include <ATen/CPUGeneratorImpl.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <mutex>

#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/progress.hpp"
#include "framework/core/registry.hpp"
#include "framework/train/fit_support.hpp"

namespace skinlab::train {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

RunOptions validated(const config::Config& config) {
  RunOptions o = RunOptions::from(config);
  o.require_training_sections(config);
  return o;
}

}  // namespace

std::shared_ptr<models::Model> build_model(const RunOptions& options) {
  torch::manual_seed(static_cast<std::uint64_t>(options.seed));
  return model_registry().create(options.model);
}

void check_prediction(const torch::Tensor& prediction, const data::CharacterTensors& c,
                      const RunOptions& options) {
  const bool ok = prediction.defined() && prediction.dim() == 2 &&
                  prediction.size(0) == c.num_vertices() && prediction.size(1) == c.top_k() &&
                  prediction.scalar_type() == torch::kFloat32;
  if (!ok) {
    throw Error(fmt::format(
        "model '{}' returned {} for character '{}'; expected a float32 #V×K = {}×{} distribution "
        "over the {} candidates (is the model's top_k the dataset's K?)",
        options.model["type"].as<std::string>(),
        prediction.defined() ? fmt::format("a {} tensor of shape {}", c10::toString(prediction.scalar_type()),
                                           fmt::join(prediction.sizes(), "×"))
                             : "an undefined tensor",
        c.name, c.num_vertices(), c.top_k(), c.distance));
  }
}

RunDir create_run(const config::Config& config, const RunOptions& options,
                  const std::string& run_id, const std::vector<std::string>& command) {
  RunDir run = RunDir::create(options.results_dir, options.experiment, run_id);
  run.write_config(config.to_yaml());
  run.write_env(collect_environment(static_cast<std::uint64_t>(options.seed), command));
  return run;
}

Trainer::Trainer(const config::Config& config)
    : config_(config), options_(validated(config)), data_(options_.data) {
  if (data_.part("train").empty()) {
    throw IoError(options_.data.file + ": split '" + options_.data.split +
                  "' has no training characters");
  }
  data_.convert("train");
  data_.convert("val");
  model_ = build_model(options_);
  check_checkpointable(*model_);
  initial_torch_rng_ = get_rng_state(at::detail::getDefaultCPUGenerator());
  loss_ = losses::LossSum::from(options_.losses);
  const auto parameters = model_->parameters();
  if (parameters.empty()) {
    options_.model.fail("model '" + options_.model["type"].as<std::string>() +
                        "' has no trainable parameters");
  }
  optimizer_ = std::make_unique<torch::optim::Adam>(
      parameters,
      torch::optim::AdamOptions(options_.train.lr).weight_decay(options_.train.weight_decay));
}

torch::Tensor Trainer::loss_of(const data::CharacterTensors& c, const torch::Tensor& pred,
                               std::map<std::string, double>* parts) const {
  check_prediction(pred, c, options_);
  losses::LossInputs in;
  in.pred = data::scatter_to_bones(pred, c.topk_index, c.num_bones());
  in.target = data::scatter_to_bones(c.targets, c.topk_index, c.num_bones());
  in.laplacian = c.laplacian;
  return loss_(in, parts);
}

double Trainer::step(int index, std::map<std::string, double>& parts) {
  const data::CharacterTensors& c = data_.tensors(index);
  optimizer_->zero_grad();
  std::map<std::string, double> step_parts;
  torch::Tensor loss = loss_of(c, model_->forward(c), &step_parts);
  const double value = loss.item<double>();
  if (!std::isfinite(value)) {
    throw Error(fmt::format("training loss is {} on character '{}' ({}); lower train.lr?", value,
                            c.name, parts_text(step_parts)));
  }
  loss.backward();
  optimizer_->step();
  for (const auto& [name, v] : step_parts) parts[name] += v;
  return value;
}

double Trainer::mean_loss(const std::string& part, std::map<std::string, double>* parts) {
  const std::vector<int>& indices = data_.part(part);
  const bool was_training = model_->is_training();
  model_->eval();
  torch::NoGradGuard no_grad;
  double total = 0;
  std::map<std::string, double> sums;
  for (int index : indices) {
    const data::CharacterTensors& c = data_.tensors(index);
    std::map<std::string, double> p;
    total += loss_of(c, model_->forward(c), &p).item<double>();
    for (const auto& [name, v] : p) sums[name] += v;
  }
  model_->train(was_training);
  const double n = static_cast<double>(std::max<std::size_t>(indices.size(), 1));
  if (parts) {
    parts->clear();
    for (const auto& [name, v] : sums) (*parts)[name] = v / n;
  }
  return indices.empty() ? std::nan("") : total / n;
}

TrainResult Trainer::fit(const RunDir& run, const FitLimits& limits) {
  if (fitted_) throw Error("Trainer::fit: a Trainer trains once; build a new one");
  fitted_ = true;
  const auto start = Clock::now();
  const TrainOptions& t = options_.train;
  TrainResult result;

  at::Generator torch_rng = at::detail::getDefaultCPUGenerator();
  at::Generator order_rng = at::make_generator<at::CPUGeneratorImpl>(order_seed(options_.seed));

  FitStart begun = start_fit(run, *model_, *optimizer_, options_.seed, options_.model.to_yaml(),
                             torch_rng, order_rng, initial_torch_rng_);
  TrainingState& state = begun.state;
  result.resumed = begun.resumed;
  const fs::path last = run.file(kLastCheckpoint);

  const std::vector<int>& train = data_.part("train");
  const bool have_val = !data_.part("val").empty();
  if (!have_val) {
    spdlog::warn("split '{}' has no validation characters: best.pt and early stopping use the "
                 "train loss", options_.data.split);
  }
  const std::size_t per_epoch =
      t.max_characters_per_epoch > 0
          ? std::min<std::size_t>(train.size(), static_cast<std::size_t>(t.max_characters_per_epoch))
          : train.size();
  auto stopped_early = [&] {
    return t.patience > 0 && state.best_epoch > 0 && state.epoch - state.best_epoch >= t.patience;
  };
  if (state.epoch >= t.epochs || stopped_early()) {
    spdlog::info("nothing to train: the run has finished ({} epochs{})", state.epoch,
                 stopped_early() ? ", stopped early" : "");
  }

  model_->train();
  const auto session_start = Clock::now();
  while (state.epoch < t.epochs && !stopped_early()) {
    const std::int64_t epoch = state.epoch + 1;
    const auto epoch_start = Clock::now();
    const torch::Tensor order = torch::randperm(static_cast<std::int64_t>(train.size()), order_rng,
                                                torch::TensorOptions().dtype(torch::kInt64));
    const auto* order_data = order.data_ptr<std::int64_t>();

    double train_sum = 0;
    std::map<std::string, double> train_parts;
    const std::string label = fmt::format("epoch {}/{}", epoch, t.epochs);
    for (std::size_t s = 0; s < per_epoch; ++s) {
      train_sum += step(train[static_cast<std::size_t>(order_data[s])], train_parts);
      if (t.log_every > 0 && (s + 1) % static_cast<std::size_t>(t.log_every) == 0 &&
          s + 1 < per_epoch) {
        const double elapsed = std::chrono::duration<double>(Clock::now() - epoch_start).count();
        spdlog::info("{} loss {:.5g}", Progress::format(label, s + 1, per_epoch, elapsed),
                     train_sum / static_cast<double>(s + 1));
      }
    }
    const double n = static_cast<double>(per_epoch);
    const double train_loss = train_sum / n;
    for (auto& [name, v] : train_parts) v /= n;

    std::map<std::string, double> val_parts;
    const double val_loss = have_val ? mean_loss("val", &val_parts) : std::nan("");
    const double selection = have_val ? val_loss : train_loss;
    const bool improved = record_epoch(state, epoch, selection, t.min_delta);
    state.torch_rng = get_rng_state(torch_rng);
    state.order_rng = get_rng_state(order_rng);
    const double seconds = std::chrono::duration<double>(Clock::now() - epoch_start).count();

    // Metrics first, then checkpoints: a kill in between leaves a record without its checkpoint,
    // which the resumed run drops and writes again.
    nlohmann::json record = {{"epoch", epoch},
                             {"train_loss", train_loss},
                             {"train_parts", parts_json(train_parts)},
                             {"val_loss", have_val ? nlohmann::json(val_loss) : nlohmann::json()},
                             {"val_parts", parts_json(val_parts)},
                             {"best_epoch", state.best_epoch},
                             {"best_loss", state.best_loss},
                             {"improved", improved},
                             {"characters", per_epoch},
                             {"lr", t.lr},
                             {"seconds", seconds}};
    run.append_metrics(record);
    if (improved) save_checkpoint(run.file(kBestCheckpoint), *model_, optimizer_.get(), state);
    save_checkpoint(last, *model_, optimizer_.get(), state);
    ++result.epochs_this_call;

    const double session = std::chrono::duration<double>(Clock::now() - session_start).count();
    const double eta = session / result.epochs_this_call * static_cast<double>(t.epochs - epoch);
    spdlog::info("{}: train loss {:.5g} ({}){} | {:.1f} s, ETA {}{}", label, train_loss,
                 parts_text(train_parts),
                 have_val ? fmt::format(", val loss {:.5g} ({})", val_loss, parts_text(val_parts))
                          : std::string(),
                 seconds, duration(eta), improved ? " *best*" : "");

    if (limits.stop_after_epochs > 0 && result.epochs_this_call >= limits.stop_after_epochs &&
        state.epoch < t.epochs) {
      result.interrupted = true;
      break;
    }
  }
  finish_fit(result, state, t, stopped_early(), start);
  return result;
}

}  // namespace skinlab::train

#include "framework/train/trainer.hpp"

#include <ATen/CPUGeneratorImpl.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <mutex>

#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/progress.hpp"
#include "framework/core/registry.hpp"
#include "framework/core/text.hpp"
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

losses::LossInputs loss_inputs(const data::CharacterTensors& c, const torch::Tensor& weights,
                               const std::vector<std::string>& priors) {
  losses::LossInputs in;
  in.pred = weights;
  in.target = data::scatter_to_bones(c.targets, c.topk_index, c.num_bones());
  in.laplacian = c.laplacian;
  for (const std::string& name : priors) {
    in.priors[name] =
        data::scatter_to_bones(data::prior_of(c, name, "losses"), c.topk_index, c.num_bones());
  }
  return in;
}

RunDir create_run(const config::Config& config, const RunOptions& options,
                  const std::string& run_id, const std::vector<std::string>& command) {
  RunDir run = RunDir::create(options.results_dir, options.experiment, run_id);
  run.write_config(config.to_yaml());
  run.write_env(collect_environment(static_cast<std::uint64_t>(options.seed), command));
  return run;
}

Trainer::Trainer(const config::Config& config, World* world)
    : config_(config), options_(validated(config)), data_(options_.data), world_(world) {
  if (world_ == nullptr) {
    alone_ = std::make_unique<World>(WorldOptions{});
    world_ = alone_.get();
  }
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
  std::int64_t count = 0;
  for (const auto& p : parameters) count += p.numel();
  spdlog::info("model '{}': {} parameters ({:.1f} MB of float32 gradients per step to all-reduce "
               "when data-parallel)",
               options_.model["type"].as<std::string>(), count, 4e-6 * static_cast<double>(count));
  optimizer_ = std::make_unique<torch::optim::Adam>(
      parameters,
      torch::optim::AdamOptions(options_.train.lr).weight_decay(options_.train.weight_decay));
}

torch::Tensor Trainer::loss_of(const data::CharacterTensors& c, const torch::Tensor& pred,
                               std::map<std::string, double>* parts) const {
  check_prediction(pred, c, options_);
  const torch::Tensor weights = data::scatter_to_bones(pred, c.topk_index, c.num_bones());
  return loss_(loss_inputs(c, weights, loss_.priors()), parts);
}

double Trainer::step(const std::vector<int>& indices, std::size_t step_characters,
                     std::map<std::string, double>& parts) {
  optimizer_->zero_grad();
  double sum = 0;
  for (int index : indices) {
    const data::CharacterTensors& c = data_.tensors(index);
    std::map<std::string, double> step_parts;
    torch::Tensor loss = loss_of(c, model_->forward(c), &step_parts);
    const double value = loss.item<double>();
    if (!std::isfinite(value)) {
      throw Error(fmt::format("training loss is {} on character '{}' ({}); lower train.lr?", value,
                              c.name, parts_text(step_parts)));
    }
    loss.backward();
    sum += value;
    for (const auto& [name, v] : step_parts) parts[name] += v;
  }
  world_->sum_gradients(*model_);
  if (step_characters > 1) {
    torch::NoGradGuard no_grad;
    for (auto& p : model_->parameters()) {
      if (p.grad().defined()) p.mutable_grad().div_(static_cast<double>(step_characters));
    }
  }
  optimizer_->step();
  return sum;
}

std::vector<std::string> Trainer::part_names() const {
  std::vector<std::string> names;
  for (const auto& term : loss_.terms()) names.push_back(term.name);
  return names;
}

double Trainer::world_sum(double value, std::map<std::string, double>& parts) {
  std::vector<double> values{value};
  const std::vector<std::string> names = part_names();
  for (const auto& name : names) values.push_back(parts.count(name) ? parts.at(name) : 0.0);
  values = world_->sum(values);
  for (std::size_t i = 0; i < names.size(); ++i) parts[names[i]] = values[i + 1];
  return values[0];
}

double Trainer::mean_loss(const std::string& part, std::map<std::string, double>* parts) {
  const std::vector<int>& indices = data_.part(part);
  const bool was_training = model_->is_training();
  model_->eval();
  torch::NoGradGuard no_grad;
  double total = 0;
  std::map<std::string, double> sums;
  // Each process scores every N-th character; the sums are added over the world.
  for (std::size_t i = static_cast<std::size_t>(world_->rank()); i < indices.size();
       i += static_cast<std::size_t>(world_->size())) {
    const data::CharacterTensors& c = data_.tensors(indices[i]);
    std::map<std::string, double> p;
    total += loss_of(c, model_->forward(c), &p).item<double>();
    for (const auto& [name, v] : p) sums[name] += v;
  }
  total = world_sum(total, sums);
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

  const bool writer = world_->writer();
  FitStart begun = start_fit(run, *model_, *optimizer_, options_.seed, t, options_.model.to_yaml(),
                             torch_rng, order_rng, initial_torch_rng_, writer);
  world_->broadcast_parameters(*model_);
  TrainingState& state = begun.state;
  result.resumed = begun.resumed;
  const fs::path last = run.file(kLastCheckpoint);

  const std::vector<int>& train = data_.part("train");
  const bool have_val = !data_.part("val").empty();
  if (writer) {
    spdlog::info("split '{}': {} training and {} validation characters{}", options_.data.split,
                 train.size(), data_.part("val").size(),
                 options_.data.val_sources.empty()
                     ? ""
                     : ", validating on the sources " + joined(options_.data.val_sources));
  }
  if (!have_val && writer) {
    spdlog::warn("split '{}' has no validation characters: best.pt and early stopping use the "
                 "train loss", options_.data.split);
  }
  const std::size_t per_epoch =
      t.max_characters_per_epoch > 0
          ? std::min<std::size_t>(train.size(), static_cast<std::size_t>(t.max_characters_per_epoch))
          : train.size();

  // Test hook (tests/cli): SKINLAB_TEST_KILL="<rank>:<steps>" makes that rank kill itself
  // after <steps> optimiser steps, as a crashed worker would.
  long kill_after = -1;
  if (const char* hook = std::getenv("SKINLAB_TEST_KILL")) {
    int rank = -1;
    if (std::sscanf(hook, "%d:%ld", &rank, &kill_after) != 2 || rank != world_->rank()) kill_after = -1;
  }
  long steps_taken = 0;

  model_->train();
  const auto session_start = Clock::now();
  while (!finished(state, t)) {
    const std::int64_t epoch = state.epoch + 1;
    const auto epoch_start = Clock::now();
    const torch::Tensor order = torch::randperm(static_cast<std::int64_t>(train.size()), order_rng,
                                                torch::TensorOptions().dtype(torch::kInt64));
    const auto* order_data = order.data_ptr<std::int64_t>();

    double train_sum = 0;
    std::map<std::string, double> train_parts;
    const std::string label = fmt::format("epoch {}/{}", epoch, t.epochs);
    // A step covers the next `group` characters of the order; this process takes every N-th.
    const auto N = static_cast<std::size_t>(world_->size());
    const std::size_t group = N * static_cast<std::size_t>(t.batch);
    std::size_t logged = 0, done = 0;
    for (std::size_t g = 0; g < per_epoch; g += group) {
      const std::size_t end = std::min(per_epoch, g + group);
      std::vector<int> mine;
      for (std::size_t s = g + static_cast<std::size_t>(world_->rank()); s < end; s += N) {
        mine.push_back(train[static_cast<std::size_t>(order_data[s])]);
      }
      if (steps_taken++ == kill_after) std::raise(SIGKILL);
      train_sum += step(mine, end - g, train_parts);
      done += mine.size();
      if (t.log_every > 0 && writer && end / static_cast<std::size_t>(t.log_every) > logged &&
          end < per_epoch) {
        logged = end / static_cast<std::size_t>(t.log_every);
        const double elapsed = std::chrono::duration<double>(Clock::now() - epoch_start).count();
        spdlog::info("{} loss {:.5g}{}", Progress::format(label, end, per_epoch, elapsed),
                     train_sum / static_cast<double>(std::max<std::size_t>(done, 1)),
                     N > 1 ? " (rank 0's characters)" : "");
      }
    }
    train_sum = world_sum(train_sum, train_parts);
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
    if (writer) {
      if (N > 1) record["world_size"] = N;
      run.append_metrics(record);
      if (improved) save_checkpoint(run.file(kBestCheckpoint), *model_, optimizer_.get(), state);
      save_checkpoint(last, *model_, optimizer_.get(), state);
    }
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
  finish_fit(result, state, t, start);
  return result;
}

}  // namespace skinlab::train

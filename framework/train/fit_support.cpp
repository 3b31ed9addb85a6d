#include "framework/tensors/threads.hpp"
#include "framework/train/fit_support.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <mutex>

#include "framework/core/atomic_file.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::train {

namespace fs = std::filesystem;

torch::Tensor get_rng_state(at::Generator generator) {
  std::lock_guard<std::mutex> lock(generator.mutex());
  return generator.get_state();
}

void set_rng_state(at::Generator& generator, const torch::Tensor& state) {
  std::lock_guard<std::mutex> lock(generator.mutex());
  generator.set_state(state);
}

std::uint64_t order_seed(std::int64_t seed) {
  return static_cast<std::uint64_t>(seed) * 0x9E3779B97F4A7C15ull + 0x6A09E667F3BCC909ull;
}

std::string duration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  return fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60);
}

std::string parts_text(const std::map<std::string, double>& parts) {
  std::string out;
  for (const auto& [name, value] : parts) out += fmt::format("{}{} {:.5g}", out.empty() ? "" : ", ", name, value);
  return out;
}

nlohmann::json parts_json(const std::map<std::string, double>& parts) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [name, value] : parts) out[name] = value;
  return out;
}

void remove_stale_temporaries(const RunDir& run) {
  for (const auto& entry : fs::directory_iterator(run.path())) {
    const std::string name = entry.path().filename().string();
    for (const char* target : {kLastCheckpoint, kBestCheckpoint, "metrics.jsonl"}) {
      if (name.rfind("." + std::string(target) + ".tmp-", 0) == 0) {
        spdlog::warn("removing {} left by an interrupted write", entry.path().string());
        fs::remove(entry.path());
      }
    }
  }
}

void truncate_metrics(const RunDir& run, std::int64_t epoch) {
  const fs::path file = run.file("metrics.jsonl");
  if (!fs::exists(file)) return;
  std::string kept;
  std::size_t dropped = 0;
  for (const auto& record : run.read_metrics()) {
    if (record.contains("epoch") && record["epoch"].is_number_integer() &&
        record["epoch"].get<std::int64_t>() > epoch) {
      ++dropped;
      continue;
    }
    kept += record.dump() + "\n";
  }
  if (dropped > 0) {
    spdlog::info("dropping {} metrics record(s) after epoch {} (not checkpointed)", dropped, epoch);
    write_file_atomic(file, kept);
  }
}

bool record_epoch(TrainingState& state, std::int64_t epoch, double selection, double min_delta) {
  const bool improved = std::isfinite(selection) &&
                        (state.best_epoch == 0 || selection < state.best_loss - min_delta);
  state.epoch = epoch;
  if (improved) {
    state.best_epoch = epoch;
    state.best_loss = selection;
  }
  return improved;
}

void finish_fit(TrainResult& result, const TrainingState& state, const TrainOptions& options,
                std::chrono::steady_clock::time_point start) {
  result.early_stopped = stopped_early(state, options) && state.epoch < options.epochs;
  if (result.early_stopped && !result.interrupted) {
    spdlog::info("early stopping after epoch {}: no improvement for {} epochs (best epoch {})",
                 state.epoch, options.patience, state.best_epoch);
  }
  result.epochs = static_cast<int>(state.epoch);
  result.best_epoch = static_cast<int>(state.best_epoch);
  result.best_loss = state.best_loss;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool stopped_early(const TrainingState& state, const TrainOptions& options) {
  return options.patience > 0 && state.best_epoch > 0 &&
         state.epoch - state.best_epoch >= options.patience;
}

bool finished(const TrainingState& state, const TrainOptions& options) {
  return state.epoch >= options.epochs || stopped_early(state, options);
}

FitStart start_fit(const RunDir& run, torch::nn::Module& model, torch::optim::Optimizer& optimizer,
                   std::int64_t seed, const TrainOptions& options, const std::string& model_config,
                   at::Generator& torch_rng,
                   at::Generator& order_rng, const torch::Tensor& initial_torch_rng, bool writer) {
  if (writer) remove_stale_temporaries(run);
  FitStart start;
  TrainingState& state = start.state;
  state.seed = seed;
  state.threads = torch_threads();
  state.model_config = model_config;
  const std::filesystem::path last = run.file(kLastCheckpoint);
  if (std::filesystem::exists(last)) {
    const TrainingState saved = load_checkpoint(last, model, &optimizer);
    if (saved.seed != seed) {
      throw Error(last.string() + ": checkpoint was trained with seed " +
                  std::to_string(saved.seed) + ", the config says " + std::to_string(seed));
    }
    if (saved.threads != state.threads) {
      spdlog::warn("{} was written with {} threads, resuming with {}: the result may differ in "
                   "the last bits from an uninterrupted run",
                   last.string(), saved.threads, state.threads);
    }
    state.epoch = saved.epoch;
    state.best_epoch = saved.best_epoch;
    state.best_loss = saved.best_loss;
    start.extra = saved.extra;
    set_rng_state(torch_rng, saved.torch_rng);
    set_rng_state(order_rng, saved.order_rng);
    start.resumed = true;
    const bool done = finished(state, options);
    if (writer && !done) {
      const GitState& git = build_git_state();
      run.record_resume({{"after_epoch", state.epoch},
                         {"git_commit", git.commit},
                         {"git_dirty", git.dirty},
                         {"threads", state.threads},
                         {"time_utc", utc_time_text()}});
    }
    spdlog::info("resuming {} after epoch {} (best epoch {}, loss {:.6g})", run.path().string(),
                 state.epoch, state.best_epoch, state.best_loss);
    if (writer && done) {
      spdlog::info("nothing to train: the run has finished ({} epochs{})", state.epoch,
                   stopped_early(state, options) ? ", stopped early" : "");
    }
  } else {
    set_rng_state(torch_rng, initial_torch_rng);
  }
  if (writer) truncate_metrics(run, state.epoch);
  return start;
}

}  // namespace skinlab::train

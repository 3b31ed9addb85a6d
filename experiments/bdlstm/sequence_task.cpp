#include "experiments/bdlstm/sequence_task.hpp"

#include <ATen/CPUGeneratorImpl.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>

#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/progress.hpp"
#include "framework/core/timing.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/fit_support.hpp"

namespace skinlab::bdlstm {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

const char* const kTaskKeys[] = {"window",         "batch",    "iterations_per_epoch",
                                 "objective",      "initial_frames", "horizons", "baseline"};

Objective objective_from(const config::Node& node) {
  Objective o;
  config::Fields f(node, "sequences.objective", {});
  const auto weight = [&](const char* key, double& value) {
    f.optional(key, value).check(std::isfinite(value) && value >= 0, key, "must be a number ≥ 0");
  };
  weight("recon", o.recon);
  weight("bidir", o.bidir);
  weight("kl", o.kl);
  weight("l2", o.l2);
  f.finish();
  return o;
}

torch::Tensor to_tensor(const Eigen::MatrixXd& m) {
  const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> f = m.cast<float>();
  return torch::from_blob(const_cast<float*>(f.data()), {f.rows(), f.cols()}, torch::kFloat32).clone();
}

Eigen::MatrixXd to_matrix(const torch::Tensor& t) {
  const torch::Tensor c = t.to(torch::kFloat64).contiguous();
  return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      c.data_ptr<double>(), c.size(0), c.size(1));
}

/// Frames outside the held-out window, for the feature scale.
std::vector<Eigen::MatrixXd> training_frames(const SequenceCharacter& c) {
  std::vector<Eigen::MatrixXd> out;
  for (const MeshSequence& s : c.sequences) {
    for (int t = 0; t < s.num_frames(); ++t) {
      if (t < s.test_begin || t >= s.test_end) out.push_back(s.features[static_cast<std::size_t>(t)]);
    }
  }
  return out;
}

std::unique_ptr<SequenceData> make_data(const train::RunData& run_data, const SequenceConfig& c) {
  return std::make_unique<SequenceData>(run_data.dataset(), c.run.data.file, c.sequences.data);
}

}  // namespace

SequenceTaskOptions SequenceTaskOptions::from(const config::Node& node) {
  SequenceTaskOptions o;
  std::vector<std::string> task_keys(std::begin(kTaskKeys), std::end(kTaskKeys));
  o.data = SequenceOptions::from(node, task_keys);
  config::Fields f(node, "sequences", {"characters", "frame_stride", "min_frames", "test_fraction", "seed"});
  f.optional("window", o.window).check(o.window >= 2, "window", "must be ≥ 2 frames");
  f.optional("batch", o.batch).check(o.batch >= 1, "batch", "must be ≥ 1");
  f.optional("iterations_per_epoch", o.iterations_per_epoch)
      .check(o.iterations_per_epoch >= 1, "iterations_per_epoch", "must be ≥ 1");
  o.objective = objective_from(f.section("objective"));
  f.optional("initial_frames", o.initial_frames);
  for (int u : o.initial_frames) {
    f.check(u >= 1 && u <= 3, "initial_frames",
            "must be 1, 2 or 3 (the last initial frame is the third frame of a start)");
  }
  f.optional("horizons", o.horizons).check(!o.horizons.empty(), "horizons", "needs at least one");
  for (int h : o.horizons) f.check(h >= 1, "horizons", "must be ≥ 1");
  std::sort(o.horizons.begin(), o.horizons.end());
  o.horizons.erase(std::unique(o.horizons.begin(), o.horizons.end()), o.horizons.end());
  f.optional("baseline", o.baseline)
      .check(o.baseline.empty() || o.baseline == "acap_extrapolation" || o.baseline == "hold",
             "baseline", "unknown baseline '" + o.baseline + "'; known: acap_extrapolation, hold");
  f.finish();
  return o;
}

SequenceConfig SequenceConfig::from(const config::Config& config) {
  SequenceConfig c;
  c.run = train::RunOptions::from(config);
  if (c.run.task != "sequence") {
    throw ConfigError(config.source() + ": task is '" + c.run.task +
                      "'; the mesh-sequence task needs `task: sequence`");
  }
  c.sequences = SequenceTaskOptions::from(c.run.sequences);
  if (c.run.model.exists()) {
    SequenceNetOptions::from(c.run.model);
    if (!c.sequences.baseline.empty()) {
      c.run.model.fail("a sequence config has a 'model' to train or a 'sequences.baseline' to "
                       "evaluate, not both");
    }
    if (c.sequences.data.characters.size() != 1) {
      c.run.sequences.fail("a bdlstm network belongs to one mesh (its fully connected layers are "
                           "sized by it; Sec. 3.2): set sequences.characters to one name");
    }
  }
  return c;
}

ScaledCharacter scale_character(const SequenceCharacter& character) {
  ScaledCharacter out;
  out.character = &character;
  out.scale = geometry::FeatureScale::fit(training_frames(character));
  for (const MeshSequence& s : character.sequences) {
    std::vector<torch::Tensor> frames;
    for (const Eigen::MatrixXd& f : s.features) frames.push_back(to_tensor(out.scale.normalise(f)));
    out.frames.push_back(std::move(frames));
  }
  return out;
}

std::shared_ptr<SequenceNet> build_network(const SequenceConfig& config,
                                           const SequenceCharacter& character) {
  torch::manual_seed(static_cast<std::uint64_t>(config.run.seed));
  return std::make_shared<SequenceNet>(SequenceNetOptions::from(config.run.model),
                                       character.num_vertices(), character.one_ring);
}

torch::Tensor sequence_loss(SequenceNet& net, const Rollout& rollout,
                            const std::vector<torch::Tensor>& window, const Objective& objective,
                            std::map<std::string, double>* parts) {
  const std::size_t L = window.size();
  const auto norm = [](const torch::Tensor& d) { return d.flatten(1).norm(2, 1).mean(); };
  torch::Tensor recon = torch::zeros({}), bidir = torch::zeros({});
  for (std::size_t i = 1; i < L; ++i) {
    recon = recon + norm(rollout.forward[i] - window[i]);
    if (!rollout.backward.empty()) recon = recon + norm(rollout.backward[i] - window[L - 1 - i]);
  }
  if (!rollout.backward.empty()) {
    for (std::size_t i = 0; i < L; ++i) bidir = bidir + norm(rollout.forward[i] - rollout.backward[L - 1 - i]);
  }
  torch::Tensor l2 = torch::zeros({});
  for (const auto& p : net.parameters()) l2 = l2 + p.pow(2).sum();
  const torch::Tensor total = objective.recon * recon + objective.bidir * bidir +
                              objective.kl * rollout.kl + objective.l2 * l2;
  if (parts) {
    (*parts)["recon"] += recon.item<double>();
    (*parts)["bidir"] += bidir.item<double>();
    (*parts)["kl"] += rollout.kl.item<double>();
    (*parts)["l2"] += l2.item<double>();
  }
  return total;
}

SequenceTrainer::SequenceTrainer(const config::Config& config)
    : options_(SequenceConfig::from(config)), run_data_([&] {
        if (!options_.sequences.baseline.empty()) {
          throw ConfigError(config.source() + ": sequences.baseline '" + options_.sequences.baseline +
                            "' is not trained; evaluate it with `skinlab eval " + config.source() +
                            " --split test`");
        }
        if (!options_.run.model.exists()) {
          throw ConfigError(config.source() + ": training needs a 'model' section, e.g. "
                            "model: {type: bdlstm}");
        }
        if (!options_.run.data_node.exists()) {
          throw ConfigError(config.source() + ": training needs a 'data' section, e.g. "
                            "data: {file: results/datasets/zeroad_sequences.h5}");
        }
        return train::RunData(options_.run.data);
      }()) {
  data_ = make_data(run_data_, options_);
  const SequenceCharacter& ch = data_->characters().front();
  scaled_ = scale_character(ch);
  // Training stretches: the frames before and after each held-out window.
  std::vector<std::pair<int, std::pair<int, int>>> stretches;
  int longest = 0;
  for (std::size_t s = 0; s < ch.sequences.size(); ++s) {
    const MeshSequence& q = ch.sequences[s];
    for (const auto& [a, b] : {std::pair{0, q.test_begin}, std::pair{q.test_end, q.num_frames()}}) {
      if (b - a >= 2) stretches.push_back({static_cast<int>(s), {a, b}});
      longest = std::max(longest, b - a);
    }
  }
  if (longest < 2) {
    throw IoError(options_.run.data.file + ": character '" + ch.name +
                  "' has no two consecutive training frames outside its held-out windows");
  }
  length_ = std::min(options_.sequences.window, longest);
  for (const auto& [s, range] : stretches) {
    for (int a = range.first; a + length_ <= range.second; ++a) windows_.emplace_back(s, a);
  }
  net_ = build_network(options_, ch);
  train::check_checkpointable(*net_);
  initial_torch_rng_ = train::get_rng_state(at::detail::getDefaultCPUGenerator());
  optimizer_ = std::make_unique<torch::optim::Adam>(
      net_->parameters(), torch::optim::AdamOptions(options_.run.train.lr));
  std::int64_t count = 0;
  for (const auto& p : net_->parameters()) count += p.numel();
  spdlog::info("sequence task: '{}' ({} vertices), {} clips, {} training windows of {} frames; "
               "{} network, {} parameters",
               ch.name, ch.num_vertices(), ch.sequences.size(), windows_.size(), length_,
               net_->options().scheme, count);
}

double SequenceTrainer::iterate(at::Generator& rng, std::map<std::string, double>& parts) {
  const int B = options_.sequences.batch;
  std::vector<std::vector<torch::Tensor>> columns(static_cast<std::size_t>(length_));
  for (int b = 0; b < B; ++b) {
    const auto pick = torch::randint(static_cast<std::int64_t>(windows_.size()), {1}, rng,
                                     torch::TensorOptions().dtype(torch::kInt64))
                          .item<std::int64_t>();
    const auto [s, a] = windows_[static_cast<std::size_t>(pick)];
    for (int i = 0; i < length_; ++i) {
      columns[static_cast<std::size_t>(i)].push_back(
          scaled_.frames[static_cast<std::size_t>(s)][static_cast<std::size_t>(a + i)]);
    }
  }
  std::vector<torch::Tensor> window;
  for (auto& column : columns) window.push_back(torch::stack(column));
  optimizer_->zero_grad();
  const Rollout rollout = net_->rollout(window);
  const torch::Tensor loss = sequence_loss(*net_, rollout, window, options_.sequences.objective, &parts);
  const double value = loss.item<double>();
  if (!std::isfinite(value)) {
    throw Error(fmt::format("training loss is {} on character '{}'; lower train.lr?", value,
                            scaled_.character->name));
  }
  loss.backward();
  optimizer_->step();
  return value;
}

train::TrainResult SequenceTrainer::fit(const RunDir& run, const train::FitLimits& limits) {
  if (fitted_) throw Error("SequenceTrainer::fit: a trainer trains once; build a new one");
  fitted_ = true;
  const auto start = Clock::now();
  const train::TrainOptions& t = options_.run.train;
  train::TrainResult result;
  at::Generator torch_rng = at::detail::getDefaultCPUGenerator();
  at::Generator order_rng =
      at::make_generator<at::CPUGeneratorImpl>(train::order_seed(options_.run.seed));
  train::FitStart begun = train::start_fit(run, *net_, *optimizer_, options_.run.seed,
                                           options_.run.model.to_yaml(), torch_rng, order_rng,
                                           initial_torch_rng_);
  train::TrainingState& state = begun.state;
  result.resumed = begun.resumed;
  const fs::path last = run.file(train::kLastCheckpoint);
  auto stopped_early = [&] {
    return t.patience > 0 && state.best_epoch > 0 && state.epoch - state.best_epoch >= t.patience;
  };
  net_->train();
  const auto session_start = Clock::now();
  const int iterations = options_.sequences.iterations_per_epoch;
  while (state.epoch < t.epochs && !stopped_early()) {
    const std::int64_t epoch = state.epoch + 1;
    const auto epoch_start = Clock::now();
    const std::string label = fmt::format("epoch {}/{}", epoch, t.epochs);
    double sum = 0;
    std::map<std::string, double> parts;
    for (int k = 1; k <= iterations; ++k) {
      sum += iterate(order_rng, parts);
      if (t.log_every > 0 && k % t.log_every == 0) {
        spdlog::info("{} loss {:.5g}", Progress::format(label, static_cast<std::size_t>(k),
                                                        static_cast<std::size_t>(iterations),
                                                        seconds_since(epoch_start)),
                     sum / k);
      }
    }
    const double train_loss = sum / iterations;
    for (auto& [name, value] : parts) value /= iterations;
    const bool improved = train::record_epoch(state, epoch, train_loss, t.min_delta);
    state.torch_rng = train::get_rng_state(torch_rng);
    state.order_rng = train::get_rng_state(order_rng);
    const double seconds = seconds_since(epoch_start);
    run.append_metrics({{"epoch", epoch},
                        {"train_loss", train_loss},
                        {"train_parts", train::parts_json(parts)},
                        {"val_loss", nlohmann::json()},
                        {"best_epoch", state.best_epoch},
                        {"best_loss", state.best_loss},
                        {"improved", improved},
                        {"iterations", iterations},
                        {"seconds", seconds}});
    if (improved) save_checkpoint(run.file(train::kBestCheckpoint), *net_, optimizer_.get(), state);
    save_checkpoint(last, *net_, optimizer_.get(), state);
    ++result.epochs_this_call;
    const double eta = seconds_since(session_start) / result.epochs_this_call *
                       static_cast<double>(t.epochs - epoch);
    spdlog::info("{}: train loss {:.5g} ({}) | {:.1f} s, ETA {}{}", label, train_loss,
                 train::parts_text(parts), seconds, train::duration(eta), improved ? " *best*" : "");
    if (limits.stop_after_epochs > 0 && result.epochs_this_call >= limits.stop_after_epochs &&
        state.epoch < t.epochs) {
      result.interrupted = true;
      break;
    }
  }
  train::finish_fit(result, state, t, stopped_early(), start);
  return result;
}

namespace {

/// Sums of one metric over a character's predictions.
struct Tally {
  double sum = 0;
  int count = 0;
  void add(double v) {
    sum += v;
    ++count;
  }
};

double mean_distance_mm(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return 1000.0 * (a - b).rowwise().norm().mean();
}

}  // namespace

eval::EvalReport evaluate_sequence(const RunDir& run, const eval::EvalOptions& options) {
  const auto start = Clock::now();
  if (options.part != "test") {
    throw Error("sequence runs are evaluated on the held-out windows (part 'test'), not '" +
                options.part + "'");
  }
  const config::Config config = config::Config::load(run.file("config.yaml"), options.overrides);
  const SequenceConfig c = SequenceConfig::from(config);
  const std::string& baseline = c.sequences.baseline;
  if (baseline.empty() && !c.run.model.exists()) {
    throw ConfigError(config.source() + ": a sequence config needs a 'model' or a "
                      "'sequences.baseline' to evaluate");
  }
  if (!c.run.data_node.exists()) {
    throw ConfigError(config.source() + ": evaluating a config needs a 'data' section");
  }
  fs::path checkpoint;
  if (baseline.empty()) {
    checkpoint = train::checkpoint_file(run.path(), options.checkpoint);
    if (!fs::exists(checkpoint)) {
      throw IoError(checkpoint.string() + ": no checkpoint '" + options.checkpoint +
                    "' in this run (a run writes best.pt and last.pt after its first epoch)");
    }
  }
  train::RunData run_data(c.run.data);
  const std::unique_ptr<SequenceData> data = make_data(run_data, c);
  eval::EvalReport report;
  report.split = "held-out windows";
  report.part = options.part;
  report.checkpoint = baseline.empty() ? options.checkpoint : "none";
  torch::NoGradGuard no_grad;
  const int H = c.sequences.horizons.back();
  std::map<std::string, std::pair<double, int>> pooled;  // key → (sum of character means, count)
  Progress progress("eval sequences", data->characters().size());
  for (const SequenceCharacter& ch : data->characters()) {
    const ScaledCharacter scaled = scale_character(ch);
    std::shared_ptr<SequenceNet> net;
    if (baseline.empty()) {
      net = build_network(c, ch);
      report.epoch = static_cast<int>(train::load_checkpoint(checkpoint, *net).epoch);
      net->eval();
    }
    std::map<std::string, Tally> tally;
    for (std::size_t s = 0; s < ch.sequences.size(); ++s) {
      const MeshSequence& q = ch.sequences[s];
      const auto& frames = scaled.frames[s];
      for (int a = q.test_begin; a + 2 + c.sequences.horizons.front() < q.test_end; ++a) {
        const int l = a + 2;
        const int reach = std::min(H, q.test_end - 1 - l);  // frames l+1..l+reach are held out
        const auto ground = [&](int h) -> const Eigen::MatrixXd& {
          return q.positions[static_cast<std::size_t>(l + h)];
        };
        const auto score = [&](const std::string& key, int h, const Eigen::MatrixXd& features) {
          tally[key].add(mean_distance_mm(ch.acap->decode(features, ground(h)), ground(h)));
        };
        std::map<int, std::vector<torch::Tensor>> generated;  // u → frames l+1..l+reach
        if (net) {
          for (int u : c.sequences.initial_frames) {
            std::vector<torch::Tensor> initial;
            for (int t = l - u + 1; t <= l; ++t) initial.push_back(frames[static_cast<std::size_t>(t)].unsqueeze(0));
            generated[u] = net->generate(initial, reach);
          }
        }
        for (int h : c.sequences.horizons) {
          if (h > reach) break;
          const Eigen::MatrixXd& F_l = q.features[static_cast<std::size_t>(l)];
          score(fmt::format("floor{}_mm", h), h, q.features[static_cast<std::size_t>(l + h)]);
          tally[fmt::format("starts{}", h)].add(1);
          if (baseline == "acap_extrapolation") {
            const Eigen::MatrixXd& F_prev = q.features[static_cast<std::size_t>(l - 1)];
            score(fmt::format("e{}_2if_mm", h), h, F_l + h * (F_l - F_prev));
          } else if (baseline == "hold") {
            score(fmt::format("e{}_1if_mm", h), h, F_l);
          } else {
            for (const auto& [u, out] : generated) {
              const Eigen::MatrixXd scaled_features = to_matrix(out[static_cast<std::size_t>(h - 1)].squeeze(0));
              score(fmt::format("e{}_{}if_mm", h, u), h, scaled.scale.denormalise(scaled_features));
            }
          }
        }
      }
    }
    eval::CharacterResult r;
    r.name = ch.name;
    r.vertices = ch.num_vertices();
    for (const auto& [key, t] : tally) {
      r.values[key] = key.rfind("starts", 0) == 0 ? t.sum : t.sum / t.count;
    }
    r.values["clips"] = static_cast<double>(ch.sequences.size());
    for (const auto& [key, value] : r.values) {
      pooled[key].first += value;
      ++pooled[key].second;
    }
    if (tally.empty()) {
      spdlog::warn("{}: no held-out window of '{}' holds 3 initial frames and the {}th frame",
                   c.run.data.file, ch.name, c.sequences.horizons.front());
    }
    report.characters.push_back(std::move(r));
    progress.tick();
  }
  progress.finish();
  // Characters whose windows are too short for a horizon do not report it: each mean is over
  // the characters that do.
  for (const auto& [key, sum_count] : pooled) report.mean[key] = sum_count.first / sum_count.second;
  report.seconds = seconds_since(start);
  eval::write_eval_files(
      run, report,
      {{"experiment", c.run.experiment},
       {"run", run.id()},
       {"task", "sequence"},
       {"dataset", c.run.data.file},
       {"split", report.split},
       {"part", options.part},
       {"method", baseline.empty() ? "model" : "baseline"},
       {"type", baseline.empty() ? "bdlstm/" + SequenceNetOptions::from(c.run.model).scheme : baseline},
       {"checkpoint", report.checkpoint},
       {"epoch", report.epoch},
       {"metric_definitions",
        fmt::format("e<h>_<u>if_mm: mean vertex distance in mm (character 1 m tall) of the h-th "
                    "frame after the last of u initial frames, decoded from the predicted ACAP "
                    "features with each part at its true centroid, over every start in the "
                    "held-out {:.0f}% windows (frame stride {}); floor<h>_mm: the true features "
                    "decoded; starts<h>: predictions scored (Qiao et al. Table 1)",
                    100 * c.sequences.data.test_fraction, c.sequences.data.frame_stride)}});
  return report;
}

}  // namespace skinlab::bdlstm

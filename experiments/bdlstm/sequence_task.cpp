#include "experiments/bdlstm/sequence_task.hpp"

#include <ATen/CPUGeneratorImpl.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>

#include "framework/core/atomic_file.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/progress.hpp"
#include "framework/core/timing.hpp"
#include "framework/geometry/gltf_export.hpp"
#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/orient_outward.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/fit_support.hpp"

namespace skinlab::bdlstm {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr const char* kNeedsData =
    "needs a 'data' section, e.g. data: {file: results/datasets/zeroad_sequences.h5}, or "
    "sequences.folder (a folder of OBJ sequences)";

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

/// Frames outside the test window (training and validation frames), for the feature scale: it
/// does not depend on val_fraction, so a run's scale is the same with or without validation.
std::vector<Eigen::MatrixXd> scale_frames(const SequenceCharacter& c) {
  std::vector<Eigen::MatrixXd> out;
  for (const MeshSequence& s : c.sequences) {
    for (int t = 0; t < s.num_frames(); ++t) {
      if (t < s.test_begin || t >= s.test_end) out.push_back(s.features[static_cast<std::size_t>(t)]);
    }
  }
  return out;
}

/// L_2 of Eq. 3: Σ w² over every trainable parameter of `module`.
torch::Tensor squared_weights(torch::nn::Module& module) {
  torch::Tensor l2 = torch::zeros({});
  for (const auto& p : module.parameters()) l2 = l2 + p.pow(2).sum();
  return l2;
}

/// The sequences of a config: its `sequences.folder` of OBJ sequences, else its dataset file.
std::unique_ptr<SequenceData> make_data(const SequenceConfig& c) {
  if (!c.sequences.data.folder.empty()) return std::make_unique<SequenceData>(c.sequences.data);
  const train::RunData run_data(c.run.data);
  return std::make_unique<SequenceData>(run_data.dataset(), c.run.data.file, c.sequences.data);
}

}  // namespace

SequenceTaskOptions SequenceTaskOptions::from(const config::Node& node) {
  SequenceTaskOptions o;
  std::vector<std::string> task_keys(std::begin(kTaskKeys), std::end(kTaskKeys));
  o.data = SequenceOptions::from(node, task_keys);
  config::Fields f(node, "sequences",
                   {"characters", "frame_stride", "min_frames", "test_fraction", "val_fraction", "seed",
                    "folder", "up"});
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
  c.sequences = SequenceTaskOptions::from(c.run.task_section);
  c.has_data = !c.sequences.data.folder.empty() || c.run.data_node.exists();
  if (c.run.model.exists()) {
    c.model_type = sequence_model_type(c.run.model);
    if (c.model_type == "bdlstm") {
      SequenceNetOptions::from(c.run.model);
    } else {
      MeshVaeOptions::from(c.run.model);
    }
    if (!c.sequences.baseline.empty()) {
      c.run.model.fail("a sequence config has a 'model' to train or a 'sequences.baseline' to "
                       "evaluate, not both");
    }
    if (c.sequences.data.characters.size() != 1) {
      c.run.task_section.fail("a bdlstm network belongs to one mesh (its fully connected layers are "
                           "sized by it; Sec. 3.2): set sequences.characters to one name");
    }
  }
  return c;
}

ScaledCharacter scale_character(const SequenceCharacter& character) {
  ScaledCharacter out;
  out.character = &character;
  out.scale = geometry::FeatureScale::fit(scale_frames(character));
  for (const MeshSequence& s : character.sequences) {
    std::vector<torch::Tensor> frames;
    for (const Eigen::MatrixXd& f : s.features) frames.push_back(to_tensor(out.scale.normalise(f)));
    out.frames.push_back(std::move(frames));
  }
  return out;
}

std::shared_ptr<MeshVae> build_vae(const SequenceConfig& config, const SequenceCharacter& character) {
  torch::manual_seed(static_cast<std::uint64_t>(config.run.seed));
  return std::make_shared<MeshVae>(MeshVaeOptions::from(config.run.model), character.num_vertices(),
                                   character.one_ring);
}

torch::Tensor vae_loss(MeshVae& vae, const torch::Tensor& frames, const Objective& objective,
                       std::map<std::string, double>* parts) {
  torch::Tensor kl;
  const torch::Tensor recon =
      (vae.reconstruct(frames, &kl) - frames).reshape({frames.size(0), -1}).norm(2, 1).mean();
  const torch::Tensor l2 = squared_weights(vae);
  if (parts) {
    (*parts)["recon"] += recon.item<double>();
    (*parts)["kl"] += kl.item<double>();
    (*parts)["l2"] += l2.item<double>();
  }
  return objective.recon * recon + objective.kl * kl + objective.l2 * l2;
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
  const torch::Tensor l2 = squared_weights(net);
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
    : options_(SequenceConfig::from(config)) {
  if (!options_.sequences.baseline.empty()) {
    throw ConfigError(config.source() + ": sequences.baseline '" + options_.sequences.baseline +
                      "' is not trained; evaluate it with `skinlab eval " + config.source() +
                      " --split test`");
  }
  if (!options_.run.model.exists()) {
    throw ConfigError(config.source() + ": training needs a 'model' section, e.g. "
                      "model: {type: bdlstm}");
  }
  if (!options_.has_data) throw ConfigError(config.source() + ": training " + kNeedsData);
  data_ = make_data(options_);
  const SequenceCharacter& ch = data_->characters().front();
  scaled_ = scale_character(ch);
  // Training stretches: the frames before and after each sequence's held-out windows (the test
  // and validation windows are adjacent: one span).
  std::vector<std::pair<int, std::pair<int, int>>> stretches;
  int longest = 0;
  for (std::size_t s = 0; s < ch.sequences.size(); ++s) {
    const MeshSequence& q = ch.sequences[s];
    const auto [held_begin, held_end] = q.held_out();
    for (const auto& [a, b] : {std::pair{0, held_begin}, std::pair{held_end, q.num_frames()}}) {
      if (b - a >= 2) stretches.push_back({static_cast<int>(s), {a, b}});
      longest = std::max(longest, b - a);
    }
  }
  if (longest < 2) {
    throw IoError(data_->source() + ": character '" + ch.name +
                  "' has no two consecutive training frames outside its held-out (test and "
                  "validation) windows");
  }
  length_ = std::min(options_.sequences.window, longest);
  for (const auto& [s, range] : stretches) {
    for (int a = range.first; a + length_ <= range.second; ++a) windows_.emplace_back(s, a);
  }
  if (options_.model_type == "mesh_vae") {
    vae_ = build_vae(options_, ch);
  } else {
    net_ = build_network(options_, ch);
  }
  // Validation: each clip's validation window, whole (a bdlstm rollout needs 2 frames).
  const int shortest = net_ ? 2 : 1;
  int skipped = 0;
  for (std::size_t s = 0; s < ch.sequences.size(); ++s) {
    const MeshSequence& q = ch.sequences[s];
    if (q.val_begin == q.val_end) continue;
    if (q.val_end - q.val_begin < shortest) {
      ++skipped;
      continue;
    }
    validation_windows_.push_back({static_cast<int>(s), q.val_begin, q.val_end});
    std::vector<torch::Tensor> frames;
    for (int t = q.val_begin; t < q.val_end; ++t) {
      frames.push_back(scaled_.frames[s][static_cast<std::size_t>(t)].unsqueeze(0));
    }
    validation_.push_back(std::move(frames));
  }
  if (skipped > 0) {
    spdlog::info("sequence task: {} clip(s) of '{}' have a 1-frame validation window, with nothing "
                 "for a rollout to predict; they are left out of the validation loss",
                 skipped, ch.name);
  }
  train::check_checkpointable(model());
  initial_torch_rng_ = train::get_rng_state(at::detail::getDefaultCPUGenerator());
  optimizer_ = std::make_unique<torch::optim::Adam>(
      model().parameters(), torch::optim::AdamOptions(options_.run.train.lr));
  std::int64_t count = 0;
  for (const auto& p : model().parameters()) count += p.numel();
  int validation_frames = 0;
  for (const Span& v : validation_windows_) validation_frames += v.end - v.begin;
  spdlog::info("sequence task: '{}' ({} vertices), {} clips, {} training windows of {} frames, "
               "{} validation windows ({} frames); {} network, {} parameters",
               ch.name, ch.num_vertices(), ch.sequences.size(), windows_.size(), length_,
               validation_windows_.size(), validation_frames,
               net_ ? "bdlstm/" + net_->options().scheme : std::string("mesh_vae"), count);
}

double SequenceTrainer::validation_loss(std::map<std::string, double>* parts) {
  if (validation_.empty()) return std::nan("");
  torch::nn::Module& m = model();
  const bool was_training = m.is_training();
  m.eval();
  torch::NoGradGuard no_grad;
  const Objective& objective = options_.sequences.objective;
  std::map<std::string, double> sums;
  if (vae_) {  // every validation frame reconstructed on its own, as in training
    std::vector<torch::Tensor> frames;
    for (const auto& window : validation_) frames.insert(frames.end(), window.begin(), window.end());
    vae_loss(*vae_, torch::cat(frames), objective, &sums);
  } else {  // each window one rollout (batch of 1), the mean over the windows
    for (const auto& window : validation_) {
      sequence_loss(*net_, net_->rollout(window), window, objective, &sums);
    }
    for (auto& [name, value] : sums) value /= static_cast<double>(validation_.size());
  }
  m.train(was_training);
  if (parts) {
    for (const auto& [name, value] : sums) (*parts)[name] += value;
  }
  // Selection is on how well unseen frames are reproduced: the reconstruction term alone. L_2
  // is a norm of the parameters and L_KL a regulariser; neither measures the frames, and on
  // windows of a few frames L_2 alone would outweigh the rest.
  return sums.at("recon");
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
  const torch::Tensor loss =
      vae_ ? vae_loss(*vae_, torch::cat(window), options_.sequences.objective, &parts)
           : sequence_loss(*net_, net_->rollout(window), window, options_.sequences.objective, &parts);
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
  train::FitStart begun = train::start_fit(run, model(), *optimizer_, options_.run.seed, t,
                                           options_.run.model.to_yaml(), torch_rng, order_rng,
                                           initial_torch_rng_);
  train::TrainingState& state = begun.state;
  result.resumed = begun.resumed;
  const fs::path last = run.file(train::kLastCheckpoint);
  const bool have_val = has_validation();
  if (!have_val) {
    spdlog::warn("{}: no validation window{}: best.pt and early stopping use the train loss",
                 data_->source(),
                 options_.sequences.data.val_fraction > 0 ? " of 2 frames or more"
                                                          : " (sequences.val_fraction is 0)");
  }
  model().train();
  const auto session_start = Clock::now();
  const int iterations = options_.sequences.iterations_per_epoch;
  while (!train::finished(state, t)) {
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
    std::map<std::string, double> val_parts;
    const double val_loss = have_val ? validation_loss(&val_parts) : std::nan("");
    const double selection = have_val ? val_loss : train_loss;
    const bool improved = train::record_epoch(state, epoch, selection, t.min_delta);
    state.torch_rng = train::get_rng_state(torch_rng);
    state.order_rng = train::get_rng_state(order_rng);
    const double seconds = seconds_since(epoch_start);
    run.append_metrics({{"epoch", epoch},
                        {"train_loss", train_loss},
                        {"train_parts", train::parts_json(parts)},
                        {"val_loss", have_val ? nlohmann::json(val_loss) : nlohmann::json()},
                        {"val_parts", train::parts_json(val_parts)},
                        {"best_epoch", state.best_epoch},
                        {"best_loss", state.best_loss},
                        {"improved", improved},
                        {"iterations", iterations},
                        {"seconds", seconds}});
    if (improved) save_checkpoint(run.file(train::kBestCheckpoint), model(), optimizer_.get(), state);
    save_checkpoint(last, model(), optimizer_.get(), state);
    ++result.epochs_this_call;
    const double eta = seconds_since(session_start) / result.epochs_this_call *
                       static_cast<double>(t.epochs - epoch);
    spdlog::info("{}: train loss {:.5g} ({}){} | {:.1f} s, ETA {}{}", label, train_loss,
                 train::parts_text(parts),
                 have_val ? fmt::format(", val loss {:.5g} ({})", val_loss, train::parts_text(val_parts))
                          : std::string(),
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
  if (!c.has_data) throw ConfigError(config.source() + ": evaluating " + kNeedsData);
  fs::path checkpoint;
  if (baseline.empty()) {
    checkpoint = train::existing_checkpoint(run.path(), options.checkpoint);
  }
  const std::unique_ptr<SequenceData> data = make_data(c);
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
    std::shared_ptr<MeshVae> vae;
    if (c.model_type == "mesh_vae") {
      vae = build_vae(c, ch);
      report.epoch = static_cast<int>(train::load_checkpoint(checkpoint, *vae).epoch);
      vae->eval();
    } else if (baseline.empty()) {
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
        } else if (vae) {  // [4]: linear extrapolation in the latent space from 2 initial frames
          generated[2] = vae->extrapolate(frames[static_cast<std::size_t>(l - 1)].unsqueeze(0),
                                          frames[static_cast<std::size_t>(l)].unsqueeze(0), reach);
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
                   data->source(), ch.name, c.sequences.horizons.front());
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
       {"dataset", data->source()},
       {"split", report.split},
       {"part", options.part},
       {"method", baseline.empty() ? "model" : "baseline"},
       {"type", !baseline.empty()            ? baseline
                : c.model_type == "mesh_vae" ? std::string("mesh_vae")
                                             : "bdlstm/" + SequenceNetOptions::from(c.run.model).scheme},
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

GeneratedSequence generate_sequence(const RunDir& run, const GenerateOptions& options,
                                    const fs::path& out) {
  if (options.initial_frames < 1 || options.frames < 1) {
    throw Error(fmt::format("generate: --init-frames ({}) and --frames ({}) must be ≥ 1",
                            options.initial_frames, options.frames));
  }
  if (fs::exists(out) && !(fs::is_directory(out) && fs::is_empty(out))) {
    throw Error(out.string() + ": exists; generate writes a new directory (choose another --out)");
  }
  const config::Config config = config::Config::load(run.file("config.yaml"), options.overrides);
  const SequenceConfig c = SequenceConfig::from(config);
  if (c.model_type == "mesh_vae") {
    throw Error(run.path().string() + ": a mesh_vae run extrapolates, it does not generate; "
                "generate needs a trained bdlstm run");
  }
  if (!c.sequences.baseline.empty() || !c.run.model.exists()) {
    throw Error(run.path().string() + ": " +
                (c.sequences.baseline.empty() ? std::string("has no model")
                                              : "is a baseline run (" + c.sequences.baseline + ")") +
                "; generate needs a trained bdlstm run");
  }
  const fs::path checkpoint = train::existing_checkpoint(run.path(), options.checkpoint);
  const std::unique_ptr<SequenceData> data = make_data(c);
  const SequenceCharacter& ch = data->characters().front();
  const ScaledCharacter scaled = scale_character(ch);
  std::size_t s = 0;
  if (!options.clip.empty()) {
    std::string clips;
    while (s < ch.sequences.size() && ch.sequences[s].clip != options.clip) {
      clips += (clips.empty() ? "" : ", ") + ch.sequences[s++].clip;
    }
    if (s == ch.sequences.size()) {
      throw Error(fmt::format("{}: character '{}' has no clip '{}' (its clips: {})", data->source(),
                              ch.name, options.clip, clips));
    }
  }
  const MeshSequence& q = ch.sequences[s];
  const int u = options.initial_frames;
  const int start = options.start < 0 ? q.test_begin : options.start;
  if (start + u > q.num_frames()) {
    throw Error(fmt::format("{}: clip '{}' of '{}' has frames 0..{}; {} initial frames from frame "
                            "{} do not fit",
                            data->source(), q.clip, ch.name, q.num_frames() - 1, u, start));
  }

  auto net = build_network(c, ch);
  GeneratedSequence result;
  result.epoch = static_cast<int>(train::load_checkpoint(checkpoint, *net).epoch);
  net->eval();
  torch::NoGradGuard no_grad;
  std::vector<torch::Tensor> initial;
  for (int t = start; t < start + u; ++t) {
    initial.push_back(scaled.frames[s][static_cast<std::size_t>(t)].unsqueeze(0));
  }
  const std::vector<torch::Tensor> generated = net->generate(initial, options.frames);

  result.character = ch.name;
  result.clip = q.clip;
  result.start = start;
  result.test_begin = q.test_begin;
  result.test_end = q.test_end;
  const Eigen::MatrixXd& last = q.positions[static_cast<std::size_t>(start + u - 1)];
  std::vector<Eigen::MatrixXd> frames(q.positions.begin() + start, q.positions.begin() + start + u);
  std::vector<Eigen::MatrixXd> truth = frames;
  nlohmann::json per_frame = nlohmann::json::array();
  for (int h = 1; h <= options.frames; ++h) {
    const Eigen::MatrixXd features =
        scaled.scale.denormalise(to_matrix(generated[static_cast<std::size_t>(h - 1)].squeeze(0)));
    frames.push_back(ch.acap->decode(features, last));
    const int t = start + u - 1 + h;
    nlohmann::json entry = {{"frame", u - 1 + h}, {"clip_frame", t}};
    if (t < q.num_frames()) {
      const Eigen::MatrixXd& ground = q.positions[static_cast<std::size_t>(t)];
      truth.push_back(ground);
      result.error_mm.push_back(mean_distance_mm(ch.acap->decode(features, ground), ground));
      entry["error_mm"] = result.error_mm.back();
      entry["held_out"] = t >= q.test_begin && t < q.test_end;
    }
    per_frame.push_back(entry);
  }

  const double fps = options.fps > 0 ? options.fps : (q.fps > 0 ? q.fps : 30.0);
  // The faces wound outwards (per part, on the bind-pose mesh), as glTF and OBJ viewers expect:
  // the dataset keeps each source's winding, and 0 A.D.'s left-handed frame winds them inwards.
  const Eigen::MatrixXi faces = geometry::orient_outward(ch.rest).F;
  write_directory_atomic(out, [&](const fs::path& staging) {
    const auto write_frames = [&](const std::string& stem, const std::vector<Eigen::MatrixXd>& list) {
      for (std::size_t t = 0; t < list.size(); ++t) {
        geometry::write_obj(staging / fmt::format("{}_{:04d}.obj", stem, t), geometry::Mesh{list[t], faces});
      }
      geometry::write_gltf_morph_animation(staging / (stem == "frame" ? "sequence.glb" : "truth.glb"),
                                           ch.name + "/" + q.clip, faces, list, fps);
    };
    write_frames("frame", frames);
    write_frames("truth", truth);
    const nlohmann::json info = {
        {"run", run.path().string()},
        {"checkpoint", options.checkpoint},
        {"epoch", result.epoch},
        {"source", data->source()},
        {"character", ch.name},
        {"clip", q.clip},
        {"start", start},
        {"held_out_window", {q.test_begin, q.test_end}},
        {"initial_frames", u},
        {"generated_frames", options.frames},
        {"fps", fps},
        {"frames", per_frame},
        {"note",
         "frame_0000..: the initial frames as given, then the generated ones (parts placed at "
         "their centroids in the last initial frame); truth_0000..: the clip over the same span; "
         "error_mm scores a generated frame as Table 1 does (parts at their true centroids), mm "
         "with the character 1 m tall"}};
    write_file_atomic(staging / "generate.json", info.dump(2) + "\n");
  });
  return result;
}

}  // namespace skinlab::bdlstm

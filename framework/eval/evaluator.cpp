#include "framework/eval/evaluator.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <set>
#include <sstream>

#include "framework/binders/binder.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/core/progress.hpp"
#include "framework/core/registry.hpp"
#include "framework/tensors/tensors.hpp"
#include "framework/eval/evaluate.hpp"
#include "framework/eval/metric.hpp"
#include "framework/eval/predictions.hpp"
#include "framework/infer/prediction.hpp"
#include "framework/losses/loss.hpp"
#include "framework/models/branched_model.hpp"
#include "framework/models/model.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/distributed.hpp"
#include "framework/train/run_data.hpp"
#include "framework/train/trainer.hpp"
#include "framework/eval/value_display.hpp"

namespace skinlab::eval {

namespace fs = std::filesystem;

namespace {

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

/// Column order: loss first, then the metrics' names in sorted order.
std::vector<std::string> columns(const std::vector<CharacterResult>& characters) {
  std::set<std::string> names;
  for (const auto& c : characters)
    for (const auto& [name, v] : c.values) names.insert(name);
  std::vector<std::string> out;
  if (names.erase("loss")) out.push_back("loss");
  out.insert(out.end(), names.begin(), names.end());
  return out;
}

}  // namespace

std::map<std::string, double> mean_values(const std::vector<CharacterResult>& characters) {
  std::vector<std::map<std::string, double>> rows;
  rows.reserve(characters.size());
  for (const auto& c : characters) rows.push_back(c.values);
  return mean_over_characters(rows);
}

namespace {

/// #V×#B float32 bone weights of a binder, checked against the Binder contract.
torch::Tensor bind_weights(const binders::Binder& binder, const std::string& type,
                           const data::PreparedCharacter& c) {
  const Eigen::MatrixXd W = binders::bind_checked(binder, c.mesh(), c.rig(),
                                                 fmt::format("binder '{}' on '{}'", type, c.name));
  const data::RowMatrixXf Wf = W.cast<float>();
  return torch::from_blob(const_cast<float*>(Wf.data()), {Wf.rows(), Wf.cols()}, torch::kFloat32)
      .clone();
}

/// #V×K: the stored prior `type` on the candidates, renormalised; uniform on a vertex where it
/// is 0 on all K. Throws Error naming the character when it has no such prior.
torch::Tensor prior_on_candidates(const data::CharacterTensors& c, const std::string& type) {
  const torch::Tensor& prior =
      data::prior_of(c, type, fmt::format("binder '{}'", binders::kPriorOnCandidates));
  const torch::Tensor sum = prior.sum(1, true);
  const torch::Tensor uniform = torch::full_like(prior, 1.0 / static_cast<double>(c.top_k()));
  return torch::where(sum > 0, prior / sum.clamp_min(1e-30), uniform);
}

}  // namespace

void write_eval_files(const RunDir& run, EvalReport& report, nlohmann::json header) {
  nlohmann::json per_character = nlohmann::json::array();
  for (const auto& c : report.characters) {
    per_character.push_back({{"character", c.name},
                             {"vertices", c.vertices},
                             {"bones", c.bones},
                             {"values", c.values}});
  }
  header["characters"] = report.characters.size();
  header["mean"] = report.mean;
  header["per_character"] = per_character;
  header["seconds"] = report.seconds;
  report.json = run.file("eval_" + report.part + ".json");
  write_file_atomic(report.json, header.dump(2) + "\n");

  const std::vector<std::string> names = columns(report.characters);
  std::string csv = "character,vertices,bones";
  for (const auto& name : names) csv += "," + csv_field(name);
  csv += "\n";
  for (const auto& c : report.characters) {
    csv += fmt::format("{},{},{}", csv_field(c.name), c.vertices, c.bones);
    for (const auto& name : names) {
      const auto it = c.values.find(name);
      csv += it == c.values.end() ? std::string(",") : fmt::format(",{}", it->second);
    }
    csv += "\n";
  }
  report.csv = run.file("eval_" + report.part + ".csv");
  write_file_atomic(report.csv, csv);
}

EvalReport evaluate(const RunDir& run, const EvalOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const config::Config config = config::Config::load(run.file("config.yaml"), options.overrides);
  const train::RunOptions o = train::RunOptions::from(config);
  // A binder run has no checkpoint and no training loss: its weights come from the geometry.
  const bool is_binder = o.binder.exists();
  fs::path checkpoint;
  if (is_binder) {
    o.require_binder_sections(config);
  } else {
    train::checkpoint_file(run.path(), options.checkpoint);  // an unknown name is reported first
    o.require_training_sections(config);
    checkpoint = train::existing_checkpoint(run.path(), options.checkpoint);
  }

  train::RunData data(o.data);
  const std::vector<int>& indices = data.part(options.part);
  if (indices.empty()) {
    throw Error(o.data.file + ": part '" + options.part + "' of split '" + o.data.split +
                "' has no characters");
  }
  std::shared_ptr<models::Model> model;
  std::shared_ptr<binders::Binder> binder;
  std::string method_type, prior_type;
  infer::PriorUse prior_use;  // what a model's rows do with its prior after the network
  std::int64_t epoch = 0;
  std::unique_ptr<losses::LossSum> loss;
  if (is_binder) {
    method_type = o.binder.required_type("binder");
    if (binders::is_reference_row(method_type)) {
      prior_type = binders::reference_row_prior(o.binder);
    } else {
      binder = binder_registry().create(o.binder);
    }
  } else {
    model = train::build_model(o);
    const models::PriorOptions prior = models::PriorOptions::of(o.model);
    prior_use = {prior.prior, prior.keep_prior_outside, prior.prior_mix};
    epoch = train::load_checkpoint(checkpoint, *model).epoch;
    loss = std::make_unique<losses::LossSum>(losses::LossSum::from(o.losses));
    model->eval();
  }
  std::vector<std::shared_ptr<Metric>> metrics;
  if (o.metrics.exists() && o.metrics.size() > 0) metrics = make_metrics(o.metrics);

  EvalReport report;
  report.split = o.data.split;
  report.part = options.part;
  report.checkpoint = is_binder ? "none" : options.checkpoint;
  report.epoch = static_cast<int>(epoch);

  std::unique_ptr<PredictionFile> h5;
  const fs::path predictions = run.file("predictions");
  const fs::path rig_dir = predictions / options.part;
  const bool writer = options.world == nullptr || options.world->writer();
  if (options.predictions && writer) {
    fs::create_directories(rig_dir);
    report.predictions = predictions;
    h5 = std::make_unique<PredictionFile>(predictions / (options.part + ".h5"));
  }

  const auto write_prediction = [&](const data::PreparedCharacter& character,
                                    const torch::Tensor& candidates, const torch::Tensor& weights) {
    const data::RowMatrixXf source = to_source_vertices(to_eigen(weights), character.vertex_map);
    write_rig_prediction(rig_dir / (character.name + "_rig.txt"), character, source);
    h5->add(character, o.data.distance, candidates, weights, source);
  };
  torch::NoGradGuard no_grad;
  // With several processes, this one evaluates positions rank, rank + N, ... of the part.
  const std::size_t N = options.world ? static_cast<std::size_t>(options.world->size()) : 1;
  const std::size_t rank = options.world ? static_cast<std::size_t>(options.world->rank()) : 0;
  Progress progress("eval " + options.part, (indices.size() + N - 1 - rank) / N);
  std::vector<CharacterResult> mine;
  std::vector<torch::Tensor> predicted;  // candidates and bone weights of each of mine
  for (std::size_t i = rank; i < indices.size(); i += N) {
    const int index = indices[i];
    const data::PreparedCharacter& character =
        data.dataset().characters[static_cast<std::size_t>(index)];
    const data::CharacterTensors& c = data.tensors(index);
    torch::Tensor candidates, weights;
    torch::Tensor network_weights;  // a model's own scatter, which its training loss scores
    if (method_type == binders::kArtistWeights) {
      weights = c.bone_weights;
      candidates = weights.gather(1, c.topk_index);
    } else if (method_type == binders::kArtistCandidates) {
      candidates = c.targets;
      weights = data::scatter_to_bones(candidates, c.topk_index, c.num_bones());
    } else if (method_type == binders::kPriorOnCandidates) {
      candidates = prior_on_candidates(c, prior_type);
      weights = data::scatter_to_bones(candidates, c.topk_index, c.num_bones());
    } else if (is_binder) {
      weights = bind_weights(*binder, method_type, character);
      candidates = weights.gather(1, c.topk_index);  // the binder's weight on each candidate
    } else {
      candidates = model->forward(c);
      train::check_prediction(candidates, c, o);
      weights = network_weights = data::scatter_to_bones(candidates, c.topk_index, c.num_bones());
      if (prior_use.acts()) {
        data::RowMatrixXd W = to_eigen(weights).cast<double>();
        infer::use_prior(W, character, o.data.distance, prior_use);
        weights = data::to_float(W);
      }
    }

    CharacterResult r;
    r.name = c.name;
    r.vertices = static_cast<int>(c.num_vertices());
    r.bones = static_cast<int>(c.num_bones());
    if (loss) {
      r.values["loss"] =
          (*loss)(train::loss_inputs(c, network_weights, loss->priors())).item<double>();
    }
    MetricInputs mi;
    mi.pred = weights;
    mi.target = c.bone_weights;
    mi.character = &character;
    for (const auto& metric : metrics) {
      for (const auto& [name, value] : (*metric)(mi)) r.values[name] = value;
    }
    mine.push_back(std::move(r));
    if (options.predictions && N == 1) {
      write_prediction(character, candidates, weights);
    } else if (options.predictions) {
      predicted.insert(predicted.end(), {candidates, weights});
    }
    progress.tick();
  }
  progress.finish();
  if (N > 1) {
    // Rank 0 gathers every process's values (JSON) and predictions (torch-serialised tensors).
    nlohmann::json values = nlohmann::json::array();
    for (const auto& r : mine) {
      values.push_back({{"name", r.name}, {"vertices", r.vertices}, {"bones", r.bones}, {"values", r.values}});
    }
    std::ostringstream tensors;
    if (options.predictions) torch::save(predicted, tensors);
    const auto all_values = options.world->gather("eval-values", values.dump(), true);
    const auto all_tensors = options.world->gather("eval-predictions", tensors.str(), true);
    if (!options.world->writer()) return report;
    std::vector<std::vector<CharacterResult>> by_rank(N);
    std::vector<std::vector<torch::Tensor>> tensors_by_rank(N);
    for (std::size_t q = 0; q < N; ++q) {
      for (const auto& v : nlohmann::json::parse(all_values[q])) {
        CharacterResult r;
        r.name = v["name"].get<std::string>();
        r.vertices = v["vertices"].get<int>();
        r.bones = v["bones"].get<int>();
        r.values = v["values"].get<std::map<std::string, double>>();
        by_rank[q].push_back(std::move(r));
      }
      if (options.predictions) {
        std::istringstream in(all_tensors[q]);
        torch::load(tensors_by_rank[q], in);
      }
    }
    mine.clear();
    for (std::size_t i = 0; i < indices.size(); ++i) {
      mine.push_back(std::move(by_rank[i % N][i / N]));
      if (h5) {
        write_prediction(data.dataset().characters[static_cast<std::size_t>(indices[i])],
                         tensors_by_rank[i % N][2 * (i / N)], tensors_by_rank[i % N][2 * (i / N) + 1]);
      }
    }
  }
  report.characters = std::move(mine);
  report.mean = mean_values(report.characters);

  if (h5) {
    h5->set_attribute("experiment", o.experiment);
    h5->set_attribute("run", run.id());
    h5->set_attribute("split", o.data.split);
    h5->set_attribute("part", options.part);
    h5->set_attribute("checkpoint", report.checkpoint);
    h5->set_attribute("epoch", epoch);
    h5->set_attribute("distance", o.data.distance);
    h5->commit();
  }

  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_eval_files(run, report,
                   {{"experiment", o.experiment},
                    {"run", run.id()},
                    {"dataset", o.data.file},
                    {"split", o.data.split},
                    {"part", options.part},
                    {"distance", o.data.distance},
                    {"method", is_binder ? "binder" : "model"},
                    {"type", is_binder ? method_type : o.model["type"].as<std::string>()},
                    {"checkpoint", report.checkpoint},
                    {"epoch", epoch}});
  return report;
}

}  // namespace skinlab::eval

// The training objective on the evaluated part, when the run has `losses:`.
SKINLAB_DECLARE_VALUE({"loss", "Loss", "", false, false, 4});

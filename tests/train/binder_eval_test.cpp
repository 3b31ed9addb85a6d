// Evaluation of a `binder:` config (weights from geometry alone): the same characters, metrics
// and output files as a trained model, no checkpoint and no loss, the binder's contract checked
// (a bad row is an error naming the vertex), `model` + `binder` in one config rejected, and the
// artist's own weights scored as a prediction (the ceilings).

#include <gtest/gtest.h>

#include <fstream>
#include <map>

#include "framework/binders/binder.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/registry.hpp"
#include "framework/train/run_data.hpp"
#include "framework/eval/evaluator.hpp"
#include "framework/geometry/closest_point_on_segment.hpp"
#include "framework/train/trainer.hpp"
#include "tests/test_util.hpp"
#include "tests/train/train_fixtures.hpp"

namespace skinlab::testing {

/// Test-only binder: all weight on the bone nearest in straight line (ties: lower index); with
/// `broken: true` vertex 1 gets a zero row, which the evaluator must refuse.
class NearestBoneBinder final : public binders::Binder {
 public:
  struct Options {
    bool broken = false;
    static Options from(const config::Node& node) {
      Options o;
      config::Fields f(node, "binder 'test_nearest_bone'");
      f.optional("broken", o.broken);
      f.finish();
      return o;
    }
  };
  explicit NearestBoneBinder(Options o) : options_(o) {}
  Eigen::MatrixXd bind(const geometry::Mesh& mesh,
                       const geometry::Skeleton& skeleton) const override {
    const auto bones = skeleton.bones();
    Eigen::MatrixXd W = Eigen::MatrixXd::Zero(mesh.num_vertices(), static_cast<int>(bones.size()));
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      int best = 0;
      double best_d = std::numeric_limits<double>::infinity();
      for (std::size_t b = 0; b < bones.size(); ++b) {
        const double d = geometry::point_segment_distance(
            mesh.V.row(v).transpose(), skeleton.positions.row(bones[b].start).transpose(),
            skeleton.positions.row(bones[b].end).transpose());
        if (d < best_d) best_d = d, best = static_cast<int>(b);
      }
      W(v, best) = (options_.broken && v == 1) ? 0.0 : 1.0;
    }
    return W;
  }

 private:
  Options options_;
};

}  // namespace skinlab::testing

SKINLAB_REGISTER(binder, test_nearest_bone, skinlab::testing::NearestBoneBinder);

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using testing::TempDir;

std::string binder_config(const fs::path& dataset, const fs::path& results,
                          const std::string& binder) {
  return "experiment: nearest\nresults_dir: " + results.string() + "\nbinder: " + binder +
         "\nmetrics: [{type: avg_l1, prune: 0}]\n"
         "data: {file: " + dataset.string() + ", split: random, distance: euclidean}\n";
}

TEST(BinderEval, SameMetricsAndFilesAsAModelWithoutCheckpointOrLoss) {
  TempDir dir;
  const fs::path dataset = dir / "tubes.h5";
  testing::write_tube_dataset(dataset, 1, 1, 2);
  const config::Config config = config::Config::parse(
      binder_config(dataset, dir / "results", "{type: test_nearest_bone}"), "nearest.yaml");
  const train::RunOptions o = train::RunOptions::from(config);
  const RunDir run = train::create_run(config, o, "b", {"test"});
  const eval::EvalReport r = eval::evaluate(run, {});

  EXPECT_EQ(r.checkpoint, "none");
  ASSERT_EQ(r.characters.size(), 2u);
  train::RunData data(o.data);
  double sum = 0;
  for (std::size_t i = 0; i < r.characters.size(); ++i) {
    const auto& c = r.characters[i];
    EXPECT_EQ(c.values.count("loss"), 0u) << "a binder has no training loss";
    // avg_l1 by hand: Σ_b |ŵ − w| per vertex, ŵ one-hot on the nearest bone (the euclidean
    // distance's first candidate), w the evaluator's target.
    const auto& t = data.tensors(data.part("test").at(i));
    ASSERT_EQ(t.name, c.name);
    const torch::Tensor one_hot =
        torch::zeros_like(t.bone_weights).scatter_(1, t.topk_index.narrow(1, 0, 1), 1.0);
    const double expected = (one_hot - t.bone_weights).abs().sum(1).mean().item<double>();
    EXPECT_NEAR(c.values.at("avg_l1"), expected, 1e-5) << c.name;
    sum += c.values.at("avg_l1");
  }
  EXPECT_NEAR(r.mean.at("avg_l1"), sum / 2, 1e-12);

  const auto json = nlohmann::json::parse(read_file(run.file("eval_test.json")));
  EXPECT_EQ(json["method"], "binder");
  EXPECT_EQ(json["type"], "test_nearest_bone");
  EXPECT_EQ(json["checkpoint"], "none");
  EXPECT_FALSE(json["mean"].contains("loss"));
  EXPECT_TRUE(fs::exists(run.file("predictions/test.h5")));
  EXPECT_TRUE(fs::exists(run.file("config.yaml")));
}

TEST(BinderEval, TheArtistsWeightsScoredAsAPredictionAreTheCeilings) {
  TempDir dir;
  const fs::path dataset = dir / "tubes.h5";
  testing::write_tube_dataset(dataset, 1, 1, 2);
  const std::string metrics =
      "\nmetrics: [{type: precision_recall, threshold: 1.0e-4, prune: 0.25}, "
      "{type: avg_l1, prune: 0}]\n";
  std::map<std::string, eval::EvalReport> reports;
  for (const char* type : {binders::kArtistWeights, binders::kArtistCandidates}) {
    std::string text = binder_config(dataset, dir / "results", std::string("{type: ") + type + "}");
    text.replace(text.find("\nmetrics:"), text.find("\ndata:") - text.find("\nmetrics:"), metrics);
    const config::Config config = config::Config::parse(text, std::string(type) + ".yaml");
    reports[type] = eval::evaluate(train::create_run(config, train::RunOptions::from(config), type, {"test"}), {});
  }
  train::RunData data(train::RunOptions::from(config::Config::parse(
      binder_config(dataset, dir / "results", "{type: artist_weights}"))).data);
  for (std::size_t i = 0; i < 2; ++i) {
    const auto& artist = reports[binders::kArtistWeights].characters[i].values;
    const auto& candidates = reports[binders::kArtistCandidates].characters[i].values;
    // The artist's weights: every kept entry is influential, and unpruned they are the target.
    EXPECT_DOUBLE_EQ(artist.at("precision"), 1.0);
    EXPECT_NEAR(artist.at("avg_l1"), 0.0, 1e-6);
    EXPECT_LE(artist.at("recall"), 1.0);
    // The K-candidate targets: exactly the scattered training targets.
    const auto& t = data.tensors(data.part("test").at(i));
    const torch::Tensor targets = data::scatter_to_bones(t.targets, t.topk_index, t.num_bones());
    EXPECT_NEAR(candidates.at("avg_l1"),
                (targets - t.bone_weights).abs().sum(1).mean().item<double>(), 1e-5);
    EXPECT_LE(candidates.at("recall"), 1.0);
  }
  // Not binders: no registry entry is needed, and the run says which reference it scored.
  EXPECT_EQ(reports[binders::kArtistWeights].checkpoint, "none");
  // Their fields are checked when the config is read: an unknown one names itself.
  const config::Config extra = config::Config::parse(
      binder_config(dataset, dir / "results", "{type: artist_weights, prior: bone_heat}"), "x.yaml");
  testing::expect_error<ConfigError>([&] { train::RunOptions::from(extra); }, {"x.yaml", "prior"});
}

TEST(BinderEval, ABadRowIsAnErrorNamingTheVertex) {
  TempDir dir;
  const fs::path dataset = dir / "tubes.h5";
  testing::write_tube_dataset(dataset, 1, 0, 1);
  const config::Config config = config::Config::parse(
      binder_config(dataset, dir / "results", "{type: test_nearest_bone, broken: true}"),
      "broken.yaml");
  const RunDir run = train::create_run(config, train::RunOptions::from(config), "b", {"test"});
  testing::expect_error<Error>([&] { eval::evaluate(run, {}); },
                               {"binder 'test_nearest_bone'", "vertex 1 has weights summing to 0"});
  EXPECT_FALSE(fs::exists(run.file("eval_test.json")));
}

TEST(BinderEval, ModelAndBinderInOneConfigIsAConfigError) {
  TempDir dir;
  const config::Config config = config::Config::parse(
      binder_config(dir / "d.h5", dir / "results", "{type: test_nearest_bone}") +
          "model: {type: heterskinnet}\n",
      "both.yaml");
  testing::expect_error<ConfigError>([&] { train::RunOptions::from(config); },
                                     {"both.yaml", "binder", "not both"});
  const config::Config binder_only = config::Config::parse(
      binder_config(dir / "d.h5", dir / "results", "{type: test_nearest_bone}"), "b.yaml");
  testing::expect_error<ConfigError>(
      [&] { train::RunOptions::from(binder_only).require_training_sections(binder_only); },
      {"b.yaml: a 'binder' is not trained", "skinlab eval b.yaml"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

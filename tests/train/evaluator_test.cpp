// Evaluation of a trained run: eval_<part>.json/.csv with per-character and mean values of the
// configured metrics (a test-only metric registered here), predictions that are valid skin
// weights, mapped back to the source vertices through the vertex map, in RigNet rig text (source
// frame) and HDF5; and clear errors for unknown parts and checkpoints.

#include <gtest/gtest.h>

#include <fstream>

#include "framework/tensors/threads.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/environment.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/h5.hpp"
#include "framework/eval/evaluator.hpp"
#include "framework/eval/metric.hpp"
#include "framework/eval/predictions.hpp"
#include "framework/geometry/rig_io.hpp"
#include "framework/train/trainer.hpp"
#include "tests/test_util.hpp"
#include "tests/train/train_fixtures.hpp"

namespace skinlab::testing {

/// Test-only metric: mean over vertices of Σ_b |pred − target| ("test_l1") and the vertex count.
class TestL1Metric final : public eval::Metric {
 public:
  struct Options {
    static Options from(const config::Node& node) {
      config::Fields(node, "metric 'test_l1'").finish();
      return {};
    }
  };
  explicit TestL1Metric(Options) {}
  std::map<std::string, double> operator()(const eval::MetricInputs& in) const override {
    TORCH_CHECK(in.character != nullptr && in.pred.sizes() == in.target.sizes());
    return {{"test_l1", (in.pred - in.target).abs().sum(1).mean().item<double>()},
            {"test_vertices", static_cast<double>(in.character->num_vertices())}};
  }
  // (`names()` joins the Metric interface on the metrics branch; harmless before.)
  std::vector<std::string> names() const { return {"test_l1", "test_vertices"}; }
};

}  // namespace skinlab::testing

SKINLAB_REGISTER(metric, test_l1, skinlab::testing::TestL1Metric);

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using testing::expect_error;
using testing::TempDir;

eval::EvalOptions options(const std::string& part, const std::string& checkpoint = "best",
                          std::vector<std::string> overrides = {}) {
  eval::EvalOptions o;
  o.part = part;
  o.checkpoint = checkpoint;
  o.overrides = std::move(overrides);
  return o;
}

struct Trained {
  TempDir dir;
  fs::path dataset;
  fs::path run;
};

/// One trained run for every test of this file (2 epochs on 4 train tubes, 2 test tubes).
const Trained& trained() {
  static Trained t = [] {
    Trained out;
    set_torch_threads(2);
    out.dataset = out.dir / "tubes.h5";
    testing::write_tube_dataset(out.dataset, 4, 1, 2);
    config::Config config = config::Config::parse(
        testing::tube_config(out.dataset, out.dir / "results", "metrics: [{type: test_l1}]\n"),
        "tubes.yaml");
    config.apply_override("train.epochs=2");
    train::Trainer trainer(config);
    const RunDir run = train::create_run(config, trainer.options(), "r", {"test"});
    trainer.fit(run);
    out.run = run.path();
    return out;
  }();
  return t;
}

TEST(Evaluate, WritesMeanAndPerCharacterValuesToJsonAndCsv) {
  const RunDir run = RunDir::open(trained().run);
  const eval::EvalReport r = eval::evaluate(run, {});
  EXPECT_EQ(r.part, "test");
  EXPECT_EQ(r.split, "random");
  EXPECT_EQ(r.checkpoint, "best");
  EXPECT_GE(r.epoch, 1);
  ASSERT_EQ(r.characters.size(), 2u);
  EXPECT_EQ(r.characters[0].name, "tube_5");  // test part: characters 5 and 6
  EXPECT_EQ(r.characters[1].name, "tube_6");
  for (const char* name : {"loss", "test_l1", "test_vertices"}) {
    ASSERT_TRUE(r.mean.count(name)) << name;
    EXPECT_DOUBLE_EQ(r.mean.at(name),
                     (r.characters[0].values.at(name) + r.characters[1].values.at(name)) / 2);
  }
  EXPECT_EQ(r.characters[0].values.at("test_vertices"), r.characters[0].vertices);
  EXPECT_GT(r.mean.at("test_l1"), 0.0);

  EXPECT_EQ(r.json, run.file("eval_test.json"));
  const auto json = nlohmann::json::parse(read_file(r.json));
  EXPECT_EQ(json["characters"], 2);
  EXPECT_EQ(json["checkpoint"], "best");
  EXPECT_EQ(json["distance"], "euclidean");
  EXPECT_DOUBLE_EQ(json["mean"]["test_l1"].get<double>(), r.mean.at("test_l1"));
  EXPECT_EQ(json["per_character"][1]["character"], "tube_6");

  const std::string csv = read_file(run.file("eval_test.csv"));
  EXPECT_EQ(csv.rfind("character,vertices,bones,loss,test_l1,test_vertices\n", 0), 0u) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
  EXPECT_NE(csv.find("\ntube_5," + std::to_string(r.characters[0].vertices) + ",6,"),
            std::string::npos) << csv;
}

TEST(Evaluate, PredictionsAreValidWeightsMappedBackToTheSourceVertices) {
  const RunDir run = RunDir::open(trained().run);
  const eval::EvalReport r = eval::evaluate(run, options("test", "last"));
  EXPECT_EQ(r.checkpoint, "last");
  EXPECT_EQ(r.epoch, 2);
  const data::Dataset dataset = data::read_dataset(trained().dataset);
  data::H5Reader h5(run.file("predictions") / "test.h5");
  EXPECT_EQ(h5.read_strings("/character_names"), (std::vector<std::string>{"tube_5", "tube_6"}));
  EXPECT_EQ(h5.read_attribute("/", "checkpoint"), "last");
  EXPECT_EQ(h5.read_int_attribute("/", "epoch"), 2);
  for (int index : {5, 6}) {
    const data::PreparedCharacter& p = dataset.characters[static_cast<std::size_t>(index)];
    const datasets::SourceCharacter source = testing::tube_character(index);
    const std::string g = "/characters/" + p.name + "/";
    const data::RowMatrixXf prepared = h5.read_float(g + "prepared_weights");
    const data::RowMatrixXf W = h5.read_float(g + "weights");
    ASSERT_EQ(prepared.rows(), p.num_vertices());
    ASSERT_EQ(prepared.cols(), p.num_bones());
    ASSERT_EQ(W.rows(), source.character.mesh.num_vertices());  // the ORIGINAL vertex count
    ASSERT_LT(p.vertex_map.size(), static_cast<std::size_t>(p.num_vertices()))
        << "merged and subdivided: the maps differ";
    for (const data::RowMatrixXf* M : {&prepared, &W}) {
      EXPECT_GE(M->minCoeff(), 0.0f);
      for (Eigen::Index v = 0; v < M->rows(); ++v) {
        EXPECT_NEAR(M->row(v).sum(), 1.0f, 1e-5f) << "vertex " << v;
        EXPECT_LE((M->row(v).array() > 0).count(), 3) << "vertex " << v;  // at most K
      }
    }
    for (std::size_t i = 0; i < p.vertex_map.size(); ++i) {
      EXPECT_EQ(W.row(static_cast<Eigen::Index>(i)), prepared.row(p.vertex_map[i])) << i;
    }
    // The seam duplicates (merged) carry the same prediction.
    EXPECT_EQ(W.row(0), W.row(8));

    // Rig text at the source vertices, in the source frame, with writable joint names.
    const geometry::Rig rig = geometry::read_rig(run.file("predictions") / "test" / (p.name + "_rig.txt"),
                                                 source.character.mesh.num_vertices());
    EXPECT_EQ(rig.skeleton.names,
              (std::vector<std::string>{"root", "spine", "neck", "head", "left_arm"}));
    EXPECT_TRUE(rig.skeleton.positions.isApprox(source.character.skeleton.positions, 1e-9))
        << rig.skeleton.positions << "\nvs\n" << source.character.skeleton.positions;
    const data::RowMatrixXf J = h5.read_float(g + "joint_weights");
    const Eigen::MatrixXd rig_weights(rig.weights);
    EXPECT_TRUE(rig_weights.isApprox(J.cast<double>(), 1e-6));
    // Joint weight = Σ of the bones starting at the joint.
    for (Eigen::Index v = 0; v < W.rows(); v += 13) {
      Eigen::VectorXf expected = Eigen::VectorXf::Zero(p.num_joints());
      for (int b = 0; b < p.num_bones(); ++b) expected[p.bones(b, 0)] += W(v, b);
      EXPECT_TRUE(J.row(v).transpose().isApprox(expected, 1e-6f)) << v;
    }
  }
}

TEST(Evaluate, UnknownPartCheckpointAndMissingCheckpointAreClearErrors) {
  const RunDir run = RunDir::open(trained().run);
  expect_error<Error>([&] { eval::evaluate(run, options("validation")); },
                      {"unknown split part 'validation'; a split has the parts train, val and test"});
  expect_error<Error>([&] { eval::evaluate(run, options("test", "first")); },
                      {"unknown checkpoint 'first'; choose best or last"});
  TempDir copy;
  fs::copy(trained().run, copy / "r", fs::copy_options::recursive);
  fs::remove(copy / "r" / "best.pt");
  expect_error<IoError>([&] { eval::evaluate(RunDir::open(copy / "r"), {}); },
                        {"best.pt: no checkpoint 'best' in this run"});
  expect_error<IoError>([&] { eval::evaluate(RunDir::open(copy / "r"), options("test", "last", {"model.hidden=4"})); },
                        {"checkpoint does not match the model", "[16, 6] in the checkpoint but [4, 6]"});
}

TEST(Predictions, ToSourceVerticesAndJointWeights) {
  data::RowMatrixXf W(2, 3);
  W << 0.5f, 0.25f, 0.25f, 0.0f, 1.0f, 0.0f;
  const data::RowMatrixXf S = eval::to_source_vertices(W, {1, 0, 1});
  EXPECT_EQ(S.rows(), 3);
  EXPECT_EQ(S.row(0), W.row(1));
  EXPECT_EQ(S.row(2), W.row(1));
  expect_error<Error>([&] { eval::to_source_vertices(W, {0, 2}); },
                      {"source vertex 1 maps to 2, outside [0, 2)"});
  data::RowMatrixXi bones(3, 2);
  bones << 0, 1, 1, 1, 0, 2;  // two bones start at joint 0
  const Eigen::MatrixXd J(eval::joint_weights_of(W, bones, 3));
  EXPECT_DOUBLE_EQ(J(0, 0), 0.75);
  EXPECT_DOUBLE_EQ(J(0, 1), 0.25);
  EXPECT_DOUBLE_EQ(J(0, 2), 0.0);
  EXPECT_DOUBLE_EQ(J(1, 1), 1.0);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

// The Eigen forward pass of `skinlab-predict` (infer/network.hpp) against the libtorch model its
// parameter file was exported from (predict/parameter_export.hpp): the bundled HeterSkinNet on
// its own test characters, and a small random network whose ops take the paths the bundled one
// does not (deeper EdgeConv MLPs, no self-loops, a one-set mesh_conv without fusing MLP,
// max-then-MLP pooling kept beside the input, a global branch that is not one broadcast row).

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>
#include <set>

#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/source.hpp"
#include "framework/eval/predictions.hpp"
#include "framework/geometry/import_character.hpp"
#include "framework/infer/eigen_predictor.hpp"
#include "framework/infer/model_dir.hpp"
#include "framework/infer/network.hpp"
#include "framework/predict/parameter_export.hpp"
#include "framework/predict/predictor.hpp"
#include "framework/train/trainer.hpp"
#include "tests/bundled_dataset.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using testing::TempDir;

const char* kPlayer =
    "/usr/share/games/minetest/games/minetest_game/mods/player_api/models/character.b3d";

double max_difference(const data::RowMatrixXf& a, const data::RowMatrixXf& b) {
  EXPECT_EQ(a.rows(), b.rows());
  EXPECT_EQ(a.cols(), b.cols());
  if (a.rows() != b.rows() || a.cols() != b.cols()) return 1e30;
  return (a - b).cwiseAbs().maxCoeff();
}

TEST(EigenNetwork, BundledModelEqualsLibtorchOnItsTestCharacters) {
  const fs::path dir = infer::default_model();
  const predict::Predictor torch_model = predict::Predictor::load(dir);
  const infer::EigenPredictor eigen_model = infer::EigenPredictor::load(dir);
  EXPECT_EQ(eigen_model.distance(), torch_model.distance());

  int compared = 0;
  for (const auto& source : testing::bundled_test_characters(dir)) {
    SCOPED_TRACE(source.character.name);
    predict::PredictOptions options;
    options.up = source.up;
    const predict::Prediction t = torch_model.predict(source.character, options);
    const predict::Prediction e = eigen_model.predict(source.character, options);
    const double candidates = max_difference(t.candidates, e.candidates);
    EXPECT_LE(candidates, 1e-5);
    EXPECT_LE(max_difference(t.prepared_weights, e.prepared_weights), 1e-5);
    EXPECT_LE(max_difference(t.source_weights, e.source_weights), 1e-5);
    // The paper's precision and recall (Sec. 4.3) of both against the artist's weights.
    const auto mt = torch_model.compare(t), me = torch_model.compare(e);
    EXPECT_EQ(mt.at("precision"), me.at("precision"));
    EXPECT_EQ(mt.at("recall"), me.at("recall"));
    EXPECT_GT(mt.at("precision"), 0.3) << "a trained model, not a random one";
    std::cout << source.character.name << ": " << t.prepared.num_vertices()
              << " prepared vertices, max |Eigen - libtorch| " << candidates
              << ", precision " << mt.at("precision") << ", recall " << mt.at("recall") << "\n";
    ++compared;
  }
  EXPECT_GE(compared, 2)
      << "at least two of the bundled model's test characters are in the bundled 0 A.D. subset";
}

/// A small random HeterSkinNet over Euclidean candidates whose ops take the other code paths.
const char* kConfig = R"(experiment: eigen_network_test
seed: 3
model:
  type: heterskinnet
  top_k: 3
  min_distance: 0.5
  stem:
    - {type: b2v, mlp: [8, 8]}
    - {type: mesh_conv, edges: [geodesic], edge_mlp: [8, 6], mlp: []}
    - {type: edge_conv, edges: one_ring, mlp: [8], self_loops: false}
  local:
    - {type: v2b, mlp: [8], variance_scale: 0.3}
    - {type: edge_conv, edges: skeleton, mlp: [8, 8]}
    - {type: global_pool, vertex_mlp: [4], bone_mlp: [], order: max_mlp, to: [vertex, bone]}
    - {type: b2v, mlp: [8]}
  global: {type: global_pool, pool: [bone], bone_mlp: [8], to: [vertex], keep_input: true}
  head: [16]
losses: [{type: kl}]
data: {file: unused.h5, split: random, distance: euclidean}
)";

/// The random network of kConfig built for `model_k` candidates (with `leaf_bias`), and the
/// player prepared with `prepared_k` (fewer when the player has fewer bones): libtorch's weights
/// and the Eigen network's through the parameter file.
struct BothPaths {
  data::PreparedCharacter prepared;
  data::RowMatrixXf libtorch, eigen;
};

BothPaths both_paths(int model_k, int prepared_k, double leaf_bias = 0) {
  std::string yaml = kConfig;
  yaml.replace(yaml.find("top_k: 3"), 8,
               fmt::format("top_k: {}\n  leaf_bias: {}", model_k, leaf_bias));
  const train::RunOptions options = train::RunOptions::from(config::Config::parse(yaml));
  const auto model = train::build_model(options);
  model->eval();
  const infer::Preparation preparation = infer::parse_preparation(
      "preprocess: {top_k: " + std::to_string(prepared_k) + "}\ndistances: [{type: euclidean}]\n",
      "preparation.yaml", ".", "euclidean");
  const geometry::Character character = geometry::import_character(kPlayer);
  BothPaths out;
  out.prepared = infer::prepare_to_predict(character, preparation, {}).prepared;
  {
    torch::NoGradGuard no_grad;
    out.libtorch = eval::to_eigen(model->forward(data::to_tensors(out.prepared, "euclidean")));
  }
  // Through the file, as skinlab-predict reads it.
  TempDir dir;
  const fs::path file = dir / "parameters.h5";
  predict::write_parameter_file(file, *model, options, "random");
  const infer::ParameterFile parameters = infer::read_parameter_file(file);
  EXPECT_EQ(parameters.model, "heterskinnet");
  EXPECT_EQ(parameters.distance, "euclidean");
  EXPECT_EQ(parameters.architecture.at("stem").at(1).at("name"), "1_mesh_conv");
  EXPECT_EQ(parameters.architecture.at("global_branch").at("keep_input"), true);
  EXPECT_EQ(parameters.parameters.size(), model->named_parameters().size());
  const infer::Network network = infer::Network::from(parameters, file);
  out.eigen = infer::forward(network, out.prepared, "euclidean");
  return out;
}

TEST(EigenNetwork, EveryOpPathEqualsLibtorch) {
  const BothPaths p = both_paths(3, 3);
  const double difference = max_difference(p.libtorch, p.eigen);
  EXPECT_LE(difference, 1e-5);
  std::cout << "random network: max |Eigen - libtorch| " << difference << "\n";
  EXPECT_LE((p.eigen.rowwise().sum().array() - 1).abs().maxCoeff(), 1e-5);
}

TEST(EigenNetwork, ACharacterWithFewerBonesThanKGetsWeightsOnItsOwnBones) {
  // K above the player's bone count: it has one candidate per bone, the network pads them to K
  // with the nearest again and drops the padded slots, in both paths alike.
  const BothPaths p = both_paths(64, 64);
  ASSERT_LT(p.prepared.num_bones(), 64);
  ASSERT_EQ(p.prepared.distances.at("euclidean").topk_index.cols(), p.prepared.num_bones());
  ASSERT_EQ(p.libtorch.cols(), p.prepared.num_bones());
  ASSERT_EQ(p.eigen.rows(), p.libtorch.rows());
  ASSERT_EQ(p.eigen.cols(), p.libtorch.cols());
  EXPECT_LE(max_difference(p.libtorch, p.eigen), 1e-5);
  EXPECT_LE((p.eigen.rowwise().sum().array() - 1).abs().maxCoeff(), 1e-5);
  EXPECT_GE(p.eigen.minCoeff(), 0.0f);

  // Fewer candidates than K on a character that has more bones is a mismatch, not padded.
  EXPECT_THROW(both_paths(3, 2), c10::Error);
}

TEST(EigenNetwork, LeafBiasMultipliesTheLeafCandidatesWeightsInBothPaths) {
  // The same random parameters (kConfig's seed) with and without a leaf bias of 0.7: each leaf
  // candidate's weight is multiplied by e^0.7 and the row renormalised, in both paths alike.
  const double bias = 0.7;
  const BothPaths plain = both_paths(3, 3);
  const BothPaths biased = both_paths(3, 3, bias);
  const auto& d = plain.prepared.distances.at("euclidean");
  const auto& bones = plain.prepared.bones;
  data::RowMatrixXf expected = plain.libtorch;
  int leaf_candidates = 0;
  for (Eigen::Index v = 0; v < expected.rows(); ++v) {
    for (Eigen::Index j = 0; j < expected.cols(); ++j) {
      const int b = d.topk_index(v, j);
      if (bones(b, 0) != bones(b, 1)) continue;
      expected(v, j) *= static_cast<float>(std::exp(bias));
      ++leaf_candidates;
    }
    expected.row(v) /= expected.row(v).sum();
  }
  ASSERT_GT(leaf_candidates, 100) << "the player's hands, feet and head are leaves";
  EXPECT_LE(max_difference(biased.libtorch, expected), 1e-5);
  EXPECT_LE(max_difference(biased.eigen, biased.libtorch), 1e-5);
  EXPECT_GT(max_difference(biased.libtorch, plain.libtorch), 1e-3);
}

TEST(EigenNetwork, ParameterFileRoundTripsAndIsWrittenWhole) {
  TempDir dir;
  infer::ParameterFile p;
  p.model = "heterskinnet";
  p.distance = "euclidean";
  p.source = "by hand";
  p.architecture = {{"top_k", 3}};
  p.parameters["a.weight"] = {{2, 3}, {1, 2, 3, 4, 5, 6}};
  p.parameters["a.bias"] = {{2}, {-1, 0.5f}};
  const fs::path file = dir / "p.h5";
  infer::write_parameter_file(file, p);
  const infer::ParameterFile back = infer::read_parameter_file(file);
  EXPECT_EQ(back.model, p.model);
  EXPECT_EQ(back.distance, p.distance);
  EXPECT_EQ(back.source, p.source);
  EXPECT_EQ(back.architecture, p.architecture);
  ASSERT_EQ(back.parameters.size(), 2u);
  EXPECT_EQ(back.parameters.at("a.weight").shape, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(back.parameters.at("a.weight").values, p.parameters.at("a.weight").values);
  EXPECT_EQ(back.parameters.at("a.bias").values, p.parameters.at("a.bias").values);

  // Values that do not fill their shape: an error naming the parameter, and no file at all.
  p.parameters["a.bias"].values.pop_back();
  const fs::path bad = dir / "bad.h5";
  testing::expect_error<Error>([&] { infer::write_parameter_file(bad, p); },
                               {"bad.h5", "'a.bias'", "1 values", "2"});
  EXPECT_FALSE(fs::exists(bad));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

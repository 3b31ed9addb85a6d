// skinlab predict's library side: a model directory in, weights for every vertex of any character
// out, mapped back to its own vertices and joints; glTF export re-imported through assimp.

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <map>

#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/data/h5.hpp"
#include "framework/geometry/gltf_export.hpp"
#include "framework/geometry/import_character.hpp"
#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/rig_io.hpp"
#include "framework/infer/eigen_predictor.hpp"
#include "framework/predict/predictor.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/trainer.hpp"
#include "tests/baselines/binder_fixtures.hpp"
#include "tests/geometry/test_meshes.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using testing::expect_error;
using testing::TempDir;

const char* kPlayer =
    "/usr/share/games/minetest/games/minetest_game/mods/player_api/models/character.b3d";

/// A tiny HeterSkinNet (random initial parameters, seed 0) over Euclidean candidates.
const char* kConfig = R"(experiment: predict_test
seed: 0
model:
  type: heterskinnet
  top_k: 3
  stem:
    - {type: b2v, mlp: [8]}
    - {type: mesh_conv, edge_mlp: [8], mlp: [8]}
  local:
    - {type: v2b, mlp: [8]}
    - {type: edge_conv, edges: skeleton, mlp: [8]}
  global: {type: global_pool, vertex_mlp: [8], bone_mlp: [8], to: [vertex], keep_input: false}
  head: [16]
losses: [{type: kl}]
data: {file: unused.h5, split: random, distance: euclidean}
metrics:
  - {type: precision_recall, threshold: 1.0e-4, prune: 0.25, average: entries}
  - {type: avg_l1, prune: 0.25}
)";

const char* kPreparation =
    "preprocess:\n  top_k: 3\n  min_vertices: 1000\n  max_vertices: 5000\n"
    "distances:\n  - {type: euclidean}\n  - {type: hollow_dist, resolution: 32}\n";

/// Writes a run directory (config.yaml, best.pt with an optimizer, a dataset file carrying only
/// the `preparation` attribute) into `dir`; returns it.
fs::path write_run(const TempDir& dir, const std::string& preparation = kPreparation) {
  const fs::path run = dir / "run";
  fs::create_directories(run);
  std::string config = kConfig;
  const std::string data = (dir / "data.h5").string();
  config.replace(config.find("unused.h5"), 9, data);
  write_file_atomic(run / "config.yaml", config);
  data::H5Writer h5(data);  // a dataset file as far as the model directory reads one
  h5.write_attribute("/", "format_version", data::kFormatVersion);
  h5.write_attribute("preparation", preparation);
  h5.commit();
  const train::RunOptions options = train::RunOptions::from(config::Config::parse(config));
  const auto model = train::build_model(options);
  torch::optim::Adam adam(model->parameters());
  train::TrainingState state;
  state.epoch = 7;
  train::save_checkpoint(run / "best.pt", *model, &adam, state);
  write_file_atomic(run / "eval_test.json", "{}");
  return run;
}

geometry::Character player() {
  geometry::ImportOptions o;
  return geometry::import_character(kPlayer, o);
}

/// Every row of W (dense copy of #V×C weights) non-negative and summing to 1.
template <class M>
void expect_rows_sum_to_one(const M& W, double tolerance = 1e-5) {
  const Eigen::MatrixXd D = Eigen::MatrixXd(W.template cast<double>());
  EXPECT_GE(D.minCoeff(), 0.0);
  for (Eigen::Index v = 0; v < D.rows(); ++v) {
    ASSERT_NEAR(D.row(v).sum(), 1.0, tolerance) << "vertex " << v;
  }
}

TEST(Predictor, RunDirectoryAndItsBundlePredictTheSameWeights) {
  TempDir dir;
  const fs::path run = write_run(dir);
  const auto from_run = predict::Predictor::load(run);
  EXPECT_NE(from_run.description().find("best.pt, epoch 7"), std::string::npos)
      << from_run.description();
  predict::bundle(run, dir / "bundle");
  for (const char* f : {"config.yaml", "preparation.yaml", "model.pt", "parameters.h5",
                        "eval_test.json", "source.txt"}) {
    EXPECT_TRUE(fs::exists(dir / "bundle" / f)) << f;
  }
  EXPECT_EQ(read_file(dir / "bundle" / "preparation.yaml"), kPreparation);
  // The bundle holds no optimizer state, so it is smaller than the training checkpoint.
  EXPECT_LT(fs::file_size(dir / "bundle" / "model.pt"), fs::file_size(run / "best.pt"));
  expect_error<IoError>([&] { predict::bundle(run, dir / "bundle"); }, {"bundle", "exists"});
  EXPECT_FALSE(fs::exists(dir / "bundle.partial"));

  // The bundle works without the dataset file.
  fs::remove(dir / "data.h5");
  const auto from_bundle = predict::Predictor::load(dir / "bundle");
  expect_error<IoError>([&] { predict::Predictor::load(run); },
                        {"data.h5", "does not exist", "bundled model"});
  const geometry::Character c = player();
  const auto a = from_run.predict(c);
  const auto b = from_bundle.predict(c);
  EXPECT_EQ(a.source_weights, b.source_weights);
  // The bundle's parameters.h5 runs without libtorch (skinlab-predict) to the same weights.
  const auto eigen = infer::EigenPredictor::load(dir / "bundle");
  EXPECT_NE(eigen.description().find("best.pt, epoch 7"), std::string::npos)
      << eigen.description();
  const auto e = eigen.predict(c);
  EXPECT_LE((e.source_weights - b.source_weights).cwiseAbs().maxCoeff(), 1e-5);
}

TEST(Predictor, EveryVertexOfARealCharacterGetsWeightsOnItsCandidates) {
  TempDir dir;
  const auto predictor = predict::Predictor::load(write_run(dir));
  const geometry::Character c = player();
  predict::StageTimes times;
  const predict::Prediction p = predictor.predict(c, {}, &times);

  // Prepared: normalised 1 m tall and subdivided into [1000, 5000] vertices (Sec. 4.1).
  EXPECT_GE(p.prepared.num_vertices(), 1000);
  EXPECT_LE(p.prepared.num_vertices(), 5000);
  EXPECT_NEAR(p.prepared.V.col(1).maxCoeff() - p.prepared.V.col(1).minCoeff(), 1.0, 1e-9);
  EXPECT_EQ(p.prepared.weights.rows(), c.mesh.num_vertices() > 0 ? p.prepared.num_vertices() : 0);
  // Back at the input: one row per input vertex, per bone and per joint.
  ASSERT_EQ(p.source_weights.rows(), c.mesh.num_vertices());
  ASSERT_EQ(p.source_weights.cols(), p.prepared.num_bones());
  ASSERT_EQ(p.joint_weights.rows(), c.mesh.num_vertices());
  ASSERT_EQ(p.joint_weights.cols(), c.skeleton.num_joints());
  expect_rows_sum_to_one(p.source_weights);
  expect_rows_sum_to_one(Eigen::MatrixXd(p.joint_weights));
  expect_rows_sum_to_one(p.prepared_weights);
  // Non-zero only on the vertex's K candidates, and pruned at 0.25 of the row maximum.
  const data::DistanceData& d = p.prepared.distances.at("euclidean");
  for (Eigen::Index v = 0; v < p.prepared_weights.rows(); ++v) {
    const float top = p.prepared_weights.row(v).maxCoeff();
    for (Eigen::Index b = 0; b < p.prepared_weights.cols(); ++b) {
      const float w = p.prepared_weights(v, b);
      if (w == 0.0f) continue;
      ASSERT_TRUE((d.topk_index.row(v).array() == static_cast<int>(b)).any()) << v << " " << b;
      ASSERT_GE(w, 0.25f * top * 0.999f) << v;
    }
  }
  EXPECT_GT(times.distance, 0.0);
  EXPECT_GT(times.network, 0.0);

  // Against the artist weights the input carried: the config's metrics, in their ranges.
  const auto values = predictor.compare(p);
  for (const char* key : {"precision", "recall", "avg_l1"}) {
    ASSERT_TRUE(values.count(key)) << key;
    EXPECT_GE(values.at(key), 0.0) << key;
  }
  EXPECT_LE(values.at("precision"), 1.0);
  EXPECT_LE(values.at("avg_l1"), 2.0);

  // The raw distribution (no pruning) differs from the pruned one and still sums to 1.
  predict::PredictOptions raw;
  raw.prune = 0;
  const auto r = predictor.predict(c, raw);
  expect_rows_sum_to_one(r.source_weights);
  EXPECT_NE(r.source_weights, p.source_weights);
}

TEST(Predictor, ObjWithRigTextWithoutWeightsAndTheRigTextOutputRoundTrips) {
  TempDir dir;
  const auto predictor = predict::Predictor::load(write_run(dir));
  const auto chain = testing::chain();
  geometry::write_obj(dir / "chain.obj", chain.mesh);
  geometry::write_rig(dir / "chain_rig.txt", chain.skeleton, {});
  const geometry::Character c = geometry::read_obj_rig(dir / "chain.obj", dir / "chain_rig.txt");
  ASSERT_FALSE(c.has_weights());
  const predict::Prediction p = predictor.predict(c);
  expect_rows_sum_to_one(Eigen::MatrixXd(p.joint_weights));
  expect_error<Error>([&] { predictor.compare(p); }, {"no skin weights"});

  geometry::write_rig(dir / "out_rig.txt", chain.skeleton, p.joint_weights);
  const geometry::Character back = geometry::read_obj_rig(dir / "chain.obj", dir / "out_rig.txt");
  EXPECT_EQ(Eigen::MatrixXd(back.weights), Eigen::MatrixXd(p.joint_weights));
  // A vertex at the top of the tube follows the upper chain more than the root joint does.
  const int top = testing::Chain::vertex(testing::Chain::kRings - 1, 0);
  EXPECT_LT(p.joint_weights.coeff(top, 0), 0.5);
}

TEST(Predictor, APreparationThatDropsWeightlessEndJointsStillPredictsEveryJoint) {
  // The model's preparation drops every character's weightless end joints (probability 1); an
  // input whose top joint carries no weight still gets a prediction over all its joints.
  TempDir dir;
  std::string preparation = kPreparation;
  preparation.insert(preparation.find("  top_k"), "  drop_weightless_leaves: 1.0\n");
  const auto predictor = predict::Predictor::load(write_run(dir, preparation));
  const auto chain = testing::chain();
  geometry::Character c;
  c.name = "chain";
  c.mesh = chain.mesh;
  c.skeleton = chain.skeleton;
  c.weights.resize(chain.mesh.num_vertices(), 4);
  for (Eigen::Index v = 0; v < chain.mesh.V.rows(); ++v) {  // j0, j1, j2 by height; j3 none
    c.weights.insert(v, chain.mesh.V(v, 1) < 0.37 ? 0 : chain.mesh.V(v, 1) < 0.63 ? 1 : 2) = 1.0;
  }
  c.validate();
  const predict::Prediction p = predictor.predict(c);
  ASSERT_EQ(p.joint_weights.cols(), 4);
  expect_rows_sum_to_one(Eigen::MatrixXd(p.joint_weights));
  EXPECT_EQ(p.prepared.num_joints(), 4);
  // the same prediction as for the input without weights: they do not steer it
  geometry::Character bare = c;
  bare.weights = geometry::SparseWeights();
  EXPECT_EQ(Eigen::MatrixXd(predictor.predict(bare).joint_weights), Eigen::MatrixXd(p.joint_weights));
  EXPECT_TRUE(predictor.compare(p).count("precision"));
  // score (as the truth is prepared: j3 dropped) takes the prediction's 4 columns
  EXPECT_TRUE(predictor.score(c, p.joint_weights).count("precision"));
}

TEST(Predictor, ModelDirectoryErrorsNameTheFile) {
  TempDir dir;
  expect_error<IoError>([&] { predict::Predictor::load(dir / "nothing"); },
                        {"nothing", "not a model directory"});
  const fs::path run = write_run(dir);
  fs::remove(run / "best.pt");
  expect_error<IoError>([&] { predict::Predictor::load(run); }, {"best.pt", "no checkpoint"});
  expect_error<Error>([&] { predict::Predictor::load(run, "newest"); }, {"newest"});
  // A preparation without the model's distance.
  TempDir other;
  const fs::path run2 = write_run(other);
  write_file_atomic(run2 / "preparation.yaml", "preprocess: {}\ndistances: [{type: hollow_dist}]\n");
  expect_error<ConfigError>([&] { predict::Predictor::load(run2); },
                            {"distance 'euclidean'", "does not list"});
}

/// glTF 2.0 written by write_gltf and imported by assimp: the same joints (names, positions,
/// parents), the same vertices and faces, and each vertex's 4 largest weights renormalised.
void expect_gltf_round_trip(const fs::path& file, const geometry::Character& c) {
  geometry::ImportOptions o;
  o.join_identical_vertices = false;
  const geometry::Character back = geometry::import_character(file, o);
  ASSERT_EQ(back.skeleton.names, c.skeleton.names);
  ASSERT_EQ(back.skeleton.parents, c.skeleton.parents);
  EXPECT_LT((back.skeleton.positions - c.skeleton.positions).cwiseAbs().maxCoeff(), 1e-5);
  ASSERT_EQ(back.mesh.num_vertices(), c.mesh.num_vertices());
  EXPECT_LT((back.mesh.V - c.mesh.V).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_EQ(back.mesh.F, c.mesh.F);
  const Eigen::MatrixXd W = Eigen::MatrixXd(c.weights);
  const Eigen::MatrixXd B = Eigen::MatrixXd(back.weights);
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    std::vector<std::pair<double, int>> row;
    for (Eigen::Index j = 0; j < W.cols(); ++j) {
      if (W(v, j) > 0) row.emplace_back(-W(v, j), static_cast<int>(j));
    }
    std::sort(row.begin(), row.end());
    row.resize(std::min<std::size_t>(row.size(), 4));
    double sum = 0;
    for (const auto& [w, j] : row) sum -= w;
    Eigen::RowVectorXd expected = Eigen::RowVectorXd::Zero(W.cols());
    for (const auto& [w, j] : row) expected(j) = -w / sum;
    ASSERT_LT((B.row(v) - expected).cwiseAbs().maxCoeff(), 1e-6) << file << " vertex " << v;
  }
}

TEST(GltfExport, PredictionReimportsWithTheSameBonesAndWeights) {
  TempDir dir;
  const auto predictor = predict::Predictor::load(write_run(dir));
  const geometry::Character input = player();
  const predict::Prediction p = predictor.predict(input);
  geometry::Character out = input;
  out.weights = p.joint_weights;
  for (const char* name : {"player.glb", "player.gltf"}) {
    geometry::write_gltf(dir / name, out);
    expect_gltf_round_trip(dir / name, out);
  }
}

TEST(GltfExport, JointsPointTheirYAxisAtTheirChildrenAndBindToIdentity) {
  // A branching skeleton: root → spine (up) → two arms (sideways) with a leaf each, and a joint
  // whose only child sits on it.
  geometry::Character c;
  c.name = "branch";
  c.mesh = testing::grid(3, 3, 0.1);
  Eigen::MatrixXd J(6, 3);
  J << 0, 0, 0,  0, 1, 0,  1, 1, 0,  -1, 1.5, 0,  2, 1, 1,  2, 1, 1;
  c.skeleton = geometry::Skeleton::from_parent_names({"root", "spine", "r_arm", "l_arm", "r_hand",
                                                      "r_tip"},
                                                     J, {"", "root", "spine", "spine", "r_arm",
                                                         "r_hand"},
                                                     "branch");
  Eigen::MatrixXd W = Eigen::MatrixXd::Constant(c.mesh.num_vertices(), 6, 1.0 / 6);
  c.weights = W.sparseView();
  TempDir dir;
  geometry::write_gltf(dir / "branch.gltf", c);

  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const std::string json = read_file(dir / "branch.gltf");  // the buffer is a data URI
  ASSERT_TRUE(loader.LoadASCIIFromString(&model, &err, &warn, json.data(),
                                         static_cast<unsigned>(json.size()), ""))
      << err;
  const auto local = [&](int j) {
    const tinygltf::Node& n = model.nodes.at(static_cast<std::size_t>(j));
    Eigen::Affine3d t = Eigen::Affine3d::Identity();
    if (!n.translation.empty()) {
      t.translate(Eigen::Vector3d(n.translation[0], n.translation[1], n.translation[2]));
    }
    if (!n.rotation.empty()) {
      t.rotate(Eigen::Quaterniond(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]));
    }
    EXPECT_TRUE(n.scale.empty() && n.matrix.empty());
    return t;
  };
  std::vector<Eigen::Affine3d> global(6);
  for (int j = 0; j < 6; ++j) {  // parents come first in this skeleton
    const int p = c.skeleton.parents[j];
    global[j] = p < 0 ? local(j) : global[p] * local(j);
  }
  const tinygltf::Accessor& a = model.accessors.at(model.skins.at(0).inverseBindMatrices);
  const tinygltf::BufferView& view = model.bufferViews.at(a.bufferView);
  const auto* ibm = reinterpret_cast<const float*>(
      model.buffers.at(view.buffer).data.data() + view.byteOffset + a.byteOffset);
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  const auto direction = [&](int j) { return (global[j].linear() * y).eval(); };
  for (int j = 0; j < 6; ++j) {
    EXPECT_LT((global[j].translation() - J.row(j).transpose()).norm(), 1e-9) << j;
    EXPECT_LT((global[j].linear() * global[j].linear().transpose() -
               Eigen::Matrix3d::Identity()).norm(), 1e-9) << j;
    Eigen::Matrix4d inverse_bind;
    for (int k = 0; k < 16; ++k) inverse_bind(k % 4, k / 4) = ibm[16 * j + k];
    EXPECT_LT((inverse_bind * global[j].matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-5)
        << j;
  }
  EXPECT_LT((direction(0) - y).norm(), 1e-9);                                 // towards spine
  EXPECT_LT((direction(1) - Eigen::Vector3d(0, 0.25, 0).normalized()).norm(), 1e-9);  // centroid
  EXPECT_LT((direction(2) - Eigen::Vector3d(1, 0, 1).normalized()).norm(), 1e-9);      // hand
  EXPECT_LT((direction(3) - direction(1)).norm(), 1e-9);  // a leaf keeps its parent's
  EXPECT_LT((direction(4) - direction(2)).norm(), 1e-9);  // its child sits on it
  // assimp reads the joints back where they were (in its own depth-first order)
  const geometry::Character back = geometry::import_character(dir / "branch.gltf");
  for (int j = 0; j < 6; ++j) {
    const int b = back.skeleton.find(c.skeleton.names[j]);
    ASSERT_GE(b, 0) << c.skeleton.names[j];
    EXPECT_LT((back.skeleton.positions.row(b) - J.row(j)).norm(), 1e-6) << c.skeleton.names[j];
  }
}

TEST(GltfExport, MoreThanFourInfluencesUseASecondSetOrAreCutToFour) {
  // A 6-joint chain over a grid; vertex weights spread over all 6 joints.
  geometry::Character c;
  c.name = "spread";
  c.mesh = testing::grid(3, 3, 0.1);
  Eigen::MatrixXd J(6, 3);
  for (int j = 0; j < 6; ++j) J.row(j) << 0.05 * j, 0.1, 0;
  c.skeleton = geometry::Skeleton::from_parent_names({"a", "b", "c", "d", "e", "f"}, J,
                                                     {"", "a", "b", "c", "d", "e"}, "spread");
  Eigen::MatrixXd W(c.mesh.num_vertices(), 6);
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    for (int j = 0; j < 6; ++j) W(v, j) = 1.0 + j + 0.1 * static_cast<double>(v % 3);
    W.row(v) /= W.row(v).sum();
  }
  c.weights = W.sparseView();
  TempDir dir;
  geometry::write_gltf(dir / "four.glb", c);
  expect_gltf_round_trip(dir / "four.glb", c);
  const std::string four = read_file(dir / "four.glb");
  EXPECT_EQ(four.find("JOINTS_1"), std::string::npos);

  geometry::GltfExportOptions eight;
  eight.max_influences = 8;
  geometry::write_gltf(dir / "eight.gltf", c, eight);
  const std::string json = read_file(dir / "eight.gltf");
  EXPECT_NE(json.find("JOINTS_1"), std::string::npos);
  EXPECT_NE(json.find("WEIGHTS_1"), std::string::npos);
  geometry::ImportOptions o;
  o.join_identical_vertices = false;
  const geometry::Character back = geometry::import_character(dir / "eight.gltf", o);
  // assimp reads both sets: all six weights come back.
  EXPECT_LT((Eigen::MatrixXd(back.weights) - W).cwiseAbs().maxCoeff(), 1e-6);

  expect_error<Error>([&] { geometry::write_gltf(dir / "x.fbx", c); }, {"x.fbx", ".glb"});
  geometry::GltfExportOptions bad;
  bad.max_influences = 9;
  expect_error<Error>([&] { geometry::write_gltf(dir / "x.glb", c, bad); }, {"max_influences"});
  c.weights = geometry::SparseWeights();
  expect_error<Error>([&] { geometry::write_gltf(dir / "x.glb", c); }, {"no weights"});
  EXPECT_FALSE(fs::exists(dir / "x.glb"));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

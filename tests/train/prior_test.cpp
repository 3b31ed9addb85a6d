// Priors (data/preprocess.hpp step 4b): a classical method's weights (bone heat) prepared into
// the dataset, gathered on the candidates, and read by HeterSkinNet with `model.prior`
// (experiments/heterskinnet/heterskinnet.hpp); training, and prediction through libtorch and
// through skinlab-predict's Eigen forward pass.

#include <gtest/gtest.h>

#include <filesystem>

#include "framework/binders/binder.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/eval/evaluator.hpp"
#include "framework/infer/eigen_predictor.hpp"
#include "framework/infer/network.hpp"
#include "framework/infer/parameters.hpp"
#include "framework/infer/prediction.hpp"
#include "framework/models/model.hpp"
#include "framework/predict/predictor.hpp"
#include "framework/tensors/tensors.hpp"
#include "framework/tensors/threads.hpp"
#include "framework/train/trainer.hpp"
#include "tests/test_util.hpp"
#include "tests/train/train_fixtures.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using testing::expect_error;

// The tubes' preparation (train_fixtures.hpp: prepared_tube) with bone heat as a prior.
constexpr const char* kPreprocess =
    "{min_vertices: 100, max_vertices: 2000, top_k: 3, priors: [{type: bone_heat}]}";

data::PreparedCharacter tube_with_bone_heat(int index) {
  const auto euclidean =
      distance_registry().create(config::Config::parse("type: euclidean").root());
  return data::preprocess(testing::tube_character(index), {{"euclidean", euclidean}},
                          data::PreprocessOptions::from(config::Config::parse(kPreprocess).root()));
}

// configs/smoke.yaml's tiny HeterSkinNet, plus `extra` model fields.
std::string tiny_heterskinnet(const std::string& extra) {
  return "{type: heterskinnet, top_k: 3, head: [16, 8], " + extra +
         "stem: [{type: b2v, mlp: [8]}, {type: v2b, mlp: [8]}, "
         "{type: mesh_conv, edge_mlp: [8], mlp: [8]}, {type: edge_conv, edges: skeleton, mlp: [8]}], "
         "local: [{type: b2v, mlp: [8]}, {type: v2b, mlp: [8]}], "
         "global: {type: global_pool, vertex_mlp: [8], bone_mlp: [8], to: [vertex], "
         "keep_input: false}}";
}

std::shared_ptr<models::Model> make_model(const std::string& extra) {
  return model_registry().create(config::Config::parse(tiny_heterskinnet(extra)).root());
}

/// The model's forward pass in eval mode with every parameter of its head set to zero.
torch::Tensor forward_with_zero_head(models::Model& model, const data::CharacterTensors& c) {
  torch::NoGradGuard no_grad;
  for (auto& p : model.named_parameters()) {
    if (p.key().rfind("head.", 0) == 0) p.value().zero_();
  }
  model.eval();
  return model.forward(c);
}

TEST(Prior, IsTheBindersWeightsOnThePreparedMeshAndBones) {
  const data::PreparedCharacter c = tube_with_bone_heat(0);
  ASSERT_EQ(c.priors.size(), 1u);
  const data::RowMatrixXf& P = c.priors.at("bone_heat");
  ASSERT_EQ(P.rows(), c.num_vertices());
  ASSERT_EQ(P.cols(), c.num_bones());
  geometry::Mesh mesh;
  mesh.V = c.V;
  mesh.F = c.F;
  const Eigen::MatrixXd expected =
      binder_registry().create(config::Config::parse("type: bone_heat").root())->bind(mesh, c.rig());
  EXPECT_LT((P.cast<double>() - expected).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((P.rowwise().sum().array() - 1.0F).abs().maxCoeff(), 1e-4);
  // Everything else is the preparation without priors.
  const data::PreparedCharacter plain = testing::prepared_tube(0);
  EXPECT_TRUE(plain.priors.empty());
  EXPECT_EQ(plain.V, c.V);
  EXPECT_EQ(plain.distances.at("euclidean").targets, c.distances.at("euclidean").targets);
}

TEST(Prior, TensorsHoldItsWeightOnEachCandidate) {
  const data::PreparedCharacter c = tube_with_bone_heat(1);
  const data::CharacterTensors t = data::to_tensors(c, "euclidean");
  ASSERT_EQ(t.priors.count("bone_heat"), 1u);
  const torch::Tensor p = t.priors.at("bone_heat");
  ASSERT_EQ(p.sizes(), (std::vector<std::int64_t>{c.num_vertices(), 3}));
  const auto a = p.accessor<float, 2>();
  const data::DistanceData& d = c.distances.at("euclidean");
  for (int v = 0; v < c.num_vertices(); ++v) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(a[v][k], c.priors.at("bone_heat")(v, d.topk_index(v, k))) << v << ", " << k;
    }
  }
  EXPECT_TRUE(data::to_tensors(testing::prepared_tube(1), "euclidean").priors.empty());
}

TEST(Prior, OptionsNameTheBadEntryAndKeepOnlyWhatTheModelReads) {
  const auto options = [](const std::string& yaml) {
    return data::PreprocessOptions::from(config::Config::parse(yaml, "p.yaml").root());
  };
  expect_error<ConfigError>([&] { options("priors: [{type: bone_heat}, {type: bone_heat}]"); },
                            {"p.yaml", "'bone_heat' is listed twice"});
  expect_error<ConfigError>([&] { options("priors: {type: bone_heat}"); },
                            {"p.yaml", "list of binder nodes"});
  expect_error<ConfigError>([&] { options("priors: [{heat: 1}]"); }, {"p.yaml", "'type'"});

  const data::PreprocessOptions both = options("priors: [{type: bone_heat}, {type: geo_voxel}]");
  ASSERT_EQ(data::keep_prior(both, "geo_voxel").priors.size(), 1u);
  EXPECT_EQ(data::keep_prior(both, "geo_voxel").priors[0].required_type("binder"), "geo_voxel");
  EXPECT_TRUE(data::keep_prior(both, "").priors.empty());
  expect_error<ConfigError>([&] { data::keep_prior(both, "magic"); },
                            {"'magic'", "bone_heat, geo_voxel", "preprocess.priors"});
  expect_error<ConfigError>([&] { data::keep_prior(options("{}"), "bone_heat"); },
                            {"'bone_heat'", "none"});
}

TEST(Prior, AHeadOfZerosGivesThePriorRenormalisedOverTheCandidates) {
  set_torch_threads(1);
  const data::CharacterTensors c = data::to_tensors(tube_with_bone_heat(2), "euclidean");
  const torch::Tensor q = c.priors.at("bone_heat") + 1e-3;  // prior_epsilon's default
  const auto with_bias = make_model("prior: bone_heat, ");
  EXPECT_TRUE(torch::allclose(forward_with_zero_head(*with_bias, c), q / q.sum(1, true), 1e-5,
                              1e-7));
  // Without the bias the prior is an input only: a zero head gives every candidate 1/K.
  const auto input_only = make_model("prior: bone_heat, prior_bias: false, ");
  EXPECT_TRUE(torch::allclose(forward_with_zero_head(*input_only, c),
                              torch::full({c.num_vertices(), 3}, 1.0 / 3), 1e-6, 1e-7));
  // The prior is an input too: the first layer of the stem reads K more vertex features.
  const auto params = [](const models::Model& m) {
    std::int64_t n = 0;
    for (const auto& p : m.parameters()) n += p.numel();
    return n;
  };
  EXPECT_GT(params(*with_bias), params(*make_model("")));
}

// #V×#B: `candidates` (#V×K) of `c`'s `distance` scattered to its bones, in doubles.
data::RowMatrixXd scattered(const data::RowMatrixXf& candidates, const data::PreparedCharacter& c,
                            const std::string& distance) {
  const data::RowMatrixXi& topk = c.distances.at(distance).topk_index;
  data::RowMatrixXd W = data::RowMatrixXd::Zero(candidates.rows(), c.num_bones());
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    for (Eigen::Index k = 0; k < topk.cols(); ++k) W(v, topk(v, k)) = candidates(v, k);
  }
  return W;
}

TEST(Prior, KeptOutsideTheCandidatesAZeroHeadGivesThePriorItself) {
  const data::PreparedCharacter ch = tube_with_bone_heat(2);
  const data::RowMatrixXi& topk = ch.distances.at("euclidean").topk_index;
  const data::RowMatrixXd P = ch.priors.at("bone_heat").cast<double>();
  const Eigen::Index K = topk.cols();
  data::RowMatrixXf renormalised(P.rows(), K), uniform(P.rows(), K);
  Eigen::VectorXd mass(P.rows());  // the prior's weight on each vertex's candidates
  for (Eigen::Index v = 0; v < P.rows(); ++v) {
    mass(v) = 0;
    for (Eigen::Index k = 0; k < K; ++k) mass(v) += P(v, topk(v, k));
    for (Eigen::Index k = 0; k < K; ++k) {
      renormalised(v, k) = static_cast<float>(P(v, topk(v, k)) / mass(v));
      uniform(v, k) = 1.0f / static_cast<float>(K);
    }
  }
  // The test means something only if the prior puts weight off some vertex's candidates.
  ASSERT_LT(mass.minCoeff(), 0.99);
  ASSERT_GT(mass.minCoeff(), 0.0);

  // The prior renormalised over the candidates (a zero head's output) gives the prior back.
  data::RowMatrixXd W = scattered(renormalised, ch, "euclidean");
  infer::keep_prior_outside(W, ch, "euclidean", "bone_heat");
  EXPECT_LT((W - P).cwiseAbs().maxCoeff(), 1e-6);

  // Any other distribution: the candidates share the prior's mass on them as it says, the other
  // bones keep the prior's weight, and every row still sums to 1.
  W = scattered(uniform, ch, "euclidean");
  infer::keep_prior_outside(W, ch, "euclidean", "bone_heat");
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    EXPECT_NEAR(W.row(v).sum(), 1.0, 1e-6);
    data::RowMatrixXd expected = P.row(v);
    for (Eigen::Index k = 0; k < K; ++k) expected(0, topk(v, k)) = mass(v) / static_cast<double>(K);
    EXPECT_LT((W.row(v) - expected).cwiseAbs().maxCoeff(), 1e-6) << "vertex " << v;
  }

  // A character without that prior names both.
  W = scattered(uniform, ch, "euclidean");
  expect_error<Error>([&] { infer::keep_prior_outside(W, ch, "euclidean", "geo_voxel"); },
                      {ch.name, "'geo_voxel' prior", "preprocess.priors"});
  expect_error<ConfigError>([&] { make_model("keep_prior_outside: true, "); },
                            {"keep_prior_outside", "prior"});
}

TEST(Prior, MixedWithTheModelsWeightsByAlpha) {
  const data::PreparedCharacter ch = tube_with_bone_heat(2);
  const data::RowMatrixXd P = ch.priors.at("bone_heat").cast<double>();
  const Eigen::Index K = ch.distances.at("euclidean").topk_index.cols();
  const data::RowMatrixXf uniform =
      data::RowMatrixXf::Constant(P.rows(), K, 1.0f / static_cast<float>(K));
  const data::RowMatrixXd model = scattered(uniform, ch, "euclidean");
  ASSERT_GT((model - P).cwiseAbs().maxCoeff(), 0.1);  // the two differ, so the mix shows

  for (const double alpha : {0.0, 0.25, 1.0}) {
    data::RowMatrixXd W = model;
    infer::mix_prior(W, ch, "bone_heat", alpha);
    EXPECT_LT((W - ((1 - alpha) * model + alpha * P)).cwiseAbs().maxCoeff(), 1e-12) << alpha;
    EXPECT_LT((W.rowwise().sum().array() - 1.0).abs().maxCoeff(), 1e-6) << alpha;
  }
  // use_prior keeps the prior off the candidates first, then mixes; nothing without a prior.
  data::RowMatrixXd both = model, by_hand = model;
  infer::use_prior(both, ch, "euclidean", {"bone_heat", true, 0.5});
  infer::keep_prior_outside(by_hand, ch, "euclidean", "bone_heat");
  infer::mix_prior(by_hand, ch, "bone_heat", 0.5);
  EXPECT_LT((both - by_hand).cwiseAbs().maxCoeff(), 1e-12);
  data::RowMatrixXd none = model;
  infer::use_prior(none, ch, "euclidean", {"", true, 0.5});
  EXPECT_EQ(none, model);

  data::RowMatrixXd W = model;
  expect_error<Error>([&] { infer::mix_prior(W, ch, "geo_voxel", 0.5); },
                      {ch.name, "prior_mix", "'geo_voxel' prior", "preprocess.priors"});
  expect_error<Error>([&] { infer::mix_prior(W, ch, "bone_heat", 1.5); },
                      {ch.name, "prior_mix", "[0, 1]", "1.5"});
  expect_error<ConfigError>([&] { make_model("prior_mix: 0.5, "); }, {"prior_mix", "prior"});
  expect_error<ConfigError>([&] { make_model("prior: bone_heat, prior_mix: -0.1, "); },
                            {"prior_mix", "[0, 1]"});
}

TEST(Prior, AModelReadingAPriorTheCharacterLacksNamesBoth) {
  const auto model = make_model("prior: bone_heat, ");
  const data::CharacterTensors c = data::to_tensors(testing::prepared_tube(0), "euclidean");
  expect_error<Error>([&] { model->forward(c); },
                      {"heterskinnet: ", "'tube_0'", "'bone_heat'", "(it has: none)",
                       "preprocess.priors: [{type: bone_heat}]"});
  expect_error<ConfigError>([&] { make_model("prior_bias: true, "); }, {"prior_bias", "prior"});
  expect_error<ConfigError>([&] { make_model("prior: bone_heat, prior_epsilon: 0, "); },
                            {"prior_epsilon", "positive"});
}

TEST(Prior, OnTheCandidatesIsAnEvaluatedRow) {
  testing::TempDir dir;
  data::Dataset d;
  for (int i = 0; i < 2; ++i) d.characters.push_back(tube_with_bone_heat(i));
  d.characters.push_back(testing::prepared_tube(2));  // without the prior
  d.splits["random"] = {{}, {}, {0, 1}};
  d.splits["no_prior"] = {{}, {}, {2}};
  d.preparation = std::string("preprocess: ") + kPreprocess + "\ndistances: [{type: euclidean}]\n";
  data::write_dataset(dir / "tubes.h5", d);
  const std::string text =
      "experiment: prior_row\nresults_dir: " + (dir / "results").string() +
      "\nbinder: {type: prior_on_candidates, prior: bone_heat}\n"
      "metrics: [{type: avg_l1, prune: 0}]\n"
      "data: {file: " + (dir / "tubes.h5").string() + ", split: random, distance: euclidean}\n";
  const config::Config config = config::Config::parse(text, "prior_row.yaml");
  const train::RunOptions o = train::RunOptions::from(config);
  const eval::EvalReport r = eval::evaluate(train::create_run(config, o, "r", {"test"}), {});
  ASSERT_EQ(r.characters.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    // By hand: the prior's weight on the candidates, renormalised, against the bone weights.
    const data::CharacterTensors c = data::to_tensors(d.characters[i], "euclidean");
    const torch::Tensor p = c.priors.at("bone_heat");
    const torch::Tensor w = data::scatter_to_bones(p / p.sum(1, true), c.topk_index, c.num_bones());
    EXPECT_NEAR(r.characters[i].values.at("avg_l1"),
                (w - c.bone_weights).abs().sum(1).mean().item<double>(), 1e-5);
  }
  // A character without the prior, and a row without `prior:`, are errors naming what is missing.
  const config::Config none = config::Config::parse(text + "\n", "none.yaml");
  const RunDir run = train::create_run(none, train::RunOptions::from(none), "n", {"test"});
  expect_error<Error>([&] { eval::evaluate(run, {{"test"}, "best", true, {"data.split=no_prior"}}); },
                      {"'tube_2'", "no 'bone_heat' prior"});
  const config::Config missing = config::Config::parse(
      "experiment: prior_row\nresults_dir: " + (dir / "results").string() +
          "\nbinder: {type: prior_on_candidates}\n"
      "data: {file: " + (dir / "tubes.h5").string() + ", split: random, distance: euclidean}\n",
      "missing.yaml");
  expect_error<ConfigError>(
      [&] {
        eval::evaluate(train::create_run(missing, train::RunOptions::from(missing), "m", {"test"}), {});
      },
      {"prior"});
}

TEST(Prior, TheLossesSeeTheirPriorsLaidOutAsThePrediction) {
  const data::CharacterTensors c = data::to_tensors(tube_with_bone_heat(1), "euclidean");
  const torch::Tensor w = data::scatter_to_bones(c.targets, c.topk_index, c.num_bones());
  // Only the priors the losses name are laid out; one the character lacks names it.
  EXPECT_TRUE(train::loss_inputs(c, w, {}).priors.empty());
  expect_error<Error>([&] { train::loss_inputs(c, w, {"geo_voxel"}); },
                      {"losses", c.name, "no 'geo_voxel' prior", "it has: bone_heat"});
  const losses::LossInputs in = train::loss_inputs(c, w, {"bone_heat"});
  ASSERT_EQ(in.priors.size(), 1u);
  const torch::Tensor p = c.priors.at("bone_heat");
  EXPECT_TRUE(torch::equal(in.priors.at("bone_heat"),
                           data::scatter_to_bones(p, c.topk_index, c.num_bones())));
  EXPECT_TRUE(torch::equal(in.target, w));
  // prior_kl of the targets: KL(prior renormalised over the candidates ‖ targets), by hand.
  const torch::Tensor q = p / p.sum(1, true);
  const torch::Tensor t = c.targets.clamp_min(1e-8);
  const double by_hand =
      torch::where(q > 0, q * (torch::log(q.clamp_min(1e-8)) - torch::log(t)), torch::zeros_like(q))
          .sum(1)
          .mean()
          .item<double>();
  const auto anchor = loss_registry().create(
      config::Config::parse("{type: prior_kl, prior: bone_heat}", "l.yaml").root());
  EXPECT_NEAR((*anchor)(in).item<double>(), by_hand, 1e-5);
}

TEST(Prior, TrainsAndPredictsWithTheRunsPreparationInLibtorchAndEigen) {
  set_torch_threads(2);
  testing::TempDir dir;
  data::Dataset d;
  for (int i = 0; i < 3; ++i) d.characters.push_back(tube_with_bone_heat(i));
  d.splits["random"] = {{0, 1}, {2}, {}};
  d.preparation = std::string("preprocess: ") + kPreprocess + "\ndistances: [{type: euclidean}]\n";
  data::write_dataset(dir / "tubes.h5", d);
  // The run's config, with `extra` model fields.
  const auto run_config = [&](const std::string& extra) {
    return config::Config::parse(
        "experiment: prior\nseed: 3\nresults_dir: " + (dir / "results").string() +
        "\nmodel: " + tiny_heterskinnet("prior: bone_heat, keep_prior_outside: true, " + extra) +
        // the anchor to the prior (losses/prior_kl.hpp) runs through training and validation too
        "\nlosses: [{type: soft_cross_entropy, weight: 1.0}, {type: prior_kl, prior: bone_heat, "
        "weight: 0.5}]\n"
        "metrics: [{type: avg_l1, prune: 0}]\n"
        "data: {file: " + (dir / "tubes.h5").string() + ", split: random, distance: euclidean}\n"
        "train: {epochs: 2, lr: 1.0e-3, patience: 0, log_every: 0}\n");
  };
  const config::Config config = run_config("");
  train::Trainer trainer(config);
  const RunDir run = train::create_run(config, trainer.options(), "p", {"test"});
  trainer.fit(run);

  // Prediction prepares the new character with the run's preparation, bone heat included.
  const predict::Predictor predictor = predict::Predictor::load(run.path());
  const predict::Prediction p = predictor.predict(testing::tube_character(5).character);
  ASSERT_EQ(p.prepared.priors.count("bone_heat"), 1u);
  const Eigen::VectorXd sums = p.joint_weights.toDense().rowwise().sum();
  EXPECT_LT((sums.array() - 1.0).abs().maxCoeff(), 1e-5);

  // skinlab-predict: the parameter file records the prior, and the Eigen forward pass, with
  // the prior computed by the binder the bundle's preparation names, equals libtorch's.
  predictor.write_parameters(run.path() / "parameters.h5");
  const infer::ParameterFile file = infer::read_parameter_file(run.path() / "parameters.h5");
  EXPECT_EQ(file.architecture.at("prior"), "bone_heat");
  EXPECT_EQ(file.architecture.at("prior_bias"), true);
  EXPECT_DOUBLE_EQ(file.architecture.at("prior_epsilon").get<double>(), 1e-3);
  const infer::EigenPredictor eigen = infer::EigenPredictor::load(run.path());
  const predict::Prediction e = eigen.predict(testing::tube_character(5).character);
  ASSERT_EQ(e.prepared.priors.count("bone_heat"), 1u);
  ASSERT_EQ(e.candidates.rows(), p.candidates.rows());
  ASSERT_EQ(e.candidates.cols(), p.candidates.cols());
  EXPECT_LE((e.candidates - p.candidates).cwiseAbs().maxCoeff(), 1e-5);

  // keep_prior_outside: both keep the prior off the candidates, as infer::keep_prior_outside
  // does to the network's output (unpruned here, so nothing else changes the weights).
  EXPECT_EQ(file.architecture.at("keep_prior_outside"), true);
  predict::PredictOptions unpruned;
  unpruned.prune = 0;
  const predict::Prediction p0 = predictor.predict(testing::tube_character(5).character, unpruned);
  const predict::Prediction e0 = eigen.predict(testing::tube_character(5).character, unpruned);
  data::RowMatrixXd completed = scattered(p0.candidates, p0.prepared, "euclidean");
  infer::keep_prior_outside(completed, p0.prepared, "euclidean", "bone_heat");
  EXPECT_LE((p0.prepared_weights.cast<double>() - completed).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LE((e0.prepared_weights - p0.prepared_weights).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_GT((completed - scattered(p0.candidates, p0.prepared, "euclidean")).cwiseAbs().maxCoeff(),
            1e-3);
  // Evaluation too; the loss is the network's own (over the candidates), so it does not change.
  const eval::EvalReport kept = eval::evaluate(run, {"val", "best", false, {}});
  const eval::EvalReport dropped =
      eval::evaluate(run, {"val", "best", false, {"model.keep_prior_outside=false"}});
  EXPECT_DOUBLE_EQ(kept.mean.at("loss"), dropped.mean.at("loss"));
  EXPECT_GT(std::abs(kept.mean.at("avg_l1") - dropped.mean.at("avg_l1")), 1e-4);

  // prior_mix: the same checkpoint under `prior_mix: 0.25` predicts 0.75·(the weights above) +
  // 0.25·(the prior) in libtorch, in the Eigen forward pass (its parameter file records α) and
  // in evaluation, whose loss is still the network's own.
  const config::Config mixed_config = run_config("prior_mix: 0.25, ");
  const RunDir mixed =
      train::create_run(mixed_config, train::RunOptions::from(mixed_config), "q", {"test"});
  fs::copy_file(train::checkpoint_file(run.path(), "best"),
                train::checkpoint_file(mixed.path(), "best"));
  const predict::Predictor mixed_predictor = predict::Predictor::load(mixed.path());
  mixed_predictor.write_parameters(mixed.path() / "parameters.h5");
  EXPECT_DOUBLE_EQ(
      infer::read_parameter_file(mixed.path() / "parameters.h5").architecture.at("prior_mix"),
      0.25);
  EXPECT_FALSE(file.architecture.contains("prior_mix"));  // written only when not 0
  const predict::Prediction pm = mixed_predictor.predict(testing::tube_character(5).character,
                                                         unpruned);
  const predict::Prediction em = infer::EigenPredictor::load(mixed.path())
                                     .predict(testing::tube_character(5).character, unpruned);
  const data::RowMatrixXd expected =
      0.75 * completed + 0.25 * p0.prepared.priors.at("bone_heat").cast<double>();
  EXPECT_LE((pm.prepared_weights.cast<double>() - expected).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LE((em.prepared_weights - pm.prepared_weights).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_GT((expected - completed).cwiseAbs().maxCoeff(), 1e-3);
  const eval::EvalReport mixed_eval =
      eval::evaluate(run, {"val", "best", false, {"model.prior_mix=0.25"}});
  EXPECT_DOUBLE_EQ(kept.mean.at("loss"), mixed_eval.mean.at("loss"));
  EXPECT_GT(std::abs(kept.mean.at("avg_l1") - mixed_eval.mean.at("avg_l1")), 1e-4);
  // The prior moves the answer: the same network with a zero prior gives other weights.
  data::PreparedCharacter without = e.prepared;
  without.priors.at("bone_heat").setZero();
  const infer::Network network = infer::Network::from(file, run.path() / "parameters.h5");
  EXPECT_GT((infer::forward(network, without, "euclidean") - e.candidates).cwiseAbs().maxCoeff(),
            1e-3);
  // A character prepared without the prior is an error naming it and the prior.
  without.priors.clear();
  expect_error<Error>([&] { infer::forward(network, without, "euclidean"); },
                      {without.name, "'bone_heat' prior"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

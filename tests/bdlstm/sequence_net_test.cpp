// The mesh-sequence BiLSTM's network (experiments/bdlstm/sequence_net.hpp) and its objective
// (sequence_task.hpp), on a 6-vertex ring: the share-weight property (Sec. 3.3: one parameter
// set that both chains use and train; the standard BD-LSTM has two, the unidirectional LSTM no
// backward chain), the batched two-chain rollout against the chains run one by one, batching
// against single sequences, generation from initial frames, Eq. 3-5 on hand-made rollouts, and
// config errors.
#include "experiments/bdlstm/sequence_net.hpp"

#include <gtest/gtest.h>

#include "experiments/bdlstm/sequence_task.hpp"
#include "framework/core/error.hpp"
#include "tests/test_util.hpp"

namespace skinlab::bdlstm {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;

constexpr std::int64_t kV = 6;

torch::Tensor ring_edges() {
  std::vector<std::int64_t> e;
  for (std::int64_t i = 0; i < kV; ++i) {
    const std::int64_t j = (i + 1) % kV;
    e.insert(e.end(), {i, j, j, i});
  }
  return torch::tensor(e, torch::kInt64).view({-1, 2});
}

SequenceNetOptions small(const std::string& scheme) {
  SequenceNetOptions o;
  o.conv = {5, 4};
  o.latent = 6;
  o.lstm_layers = 2;
  o.hidden = 7;
  o.scheme = scheme;
  return o;
}

std::vector<torch::Tensor> window(std::int64_t batch, int frames, std::uint64_t seed = 3) {
  torch::manual_seed(seed);
  std::vector<torch::Tensor> w;
  for (int t = 0; t < frames; ++t) w.push_back(0.5 * torch::randn({batch, kV, 9}));
  return w;
}

std::int64_t count(const torch::nn::Module& m) {
  std::int64_t n = 0;
  for (const auto& p : m.parameters()) n += p.numel();
  return n;
}

TEST(SequenceNet, SharedChainsAreOneParameterSet) {
  torch::manual_seed(0);
  SequenceNet shared(small("shared"), kV, ring_edges());
  SequenceNet standard(small("standard"), kV, ring_edges());
  SequenceNet unidirectional(small("unidirectional"), kV, ring_edges());
  EXPECT_EQ(&shared.forward_chain(), &shared.backward_chain());
  EXPECT_NE(&standard.forward_chain(), &standard.backward_chain());
  EXPECT_EQ(count(shared), count(shared.forward_chain()));
  EXPECT_EQ(count(standard), 2 * count(shared));  // "halves the trainable parameters"
  EXPECT_EQ(count(unidirectional), count(shared));

  // A loss on the backward chain alone trains the parameters the forward chain runs with.
  const auto w = window(2, 4);
  shared.eval();  // deterministic: z = μ
  shared.zero_grad();
  shared.rollout(w).backward.back().sum().backward();
  for (const auto& p : shared.forward_chain().named_parameters()) {
    ASSERT_TRUE(p.value().grad().defined()) << p.key();
    EXPECT_GT(p.value().grad().abs().sum().item<double>(), 0) << p.key();
  }
  // Under the standard scheme it trains only the backward chain's own copy.
  standard.eval();
  standard.zero_grad();
  standard.rollout(w).backward.back().sum().backward();
  for (const auto& p : standard.forward_chain().parameters()) {
    EXPECT_TRUE(!p.grad().defined() || p.grad().abs().sum().item<double>() == 0);
  }
  double backward_grad = 0;
  for (const auto& p : standard.backward_chain().parameters()) {
    if (p.grad().defined()) backward_grad += p.grad().abs().sum().item<double>();
  }
  EXPECT_GT(backward_grad, 0);
  EXPECT_TRUE(unidirectional.rollout(w).backward.empty());
}

TEST(SequenceNet, BatchedRolloutIsTheTwoChainsOneByOne) {
  torch::manual_seed(0);
  SequenceNet net(small("shared"), kV, ring_edges());
  net.eval();
  torch::NoGradGuard no_grad;
  const auto w = window(3, 5);
  const Rollout r = net.rollout(w);
  ASSERT_EQ(r.forward.size(), 5u);
  ASSERT_EQ(r.backward.size(), 5u);
  EXPECT_TRUE(torch::equal(r.forward.front(), w.front()));
  EXPECT_TRUE(torch::equal(r.backward.front(), w.back()));
  // By hand: the backward chain from X_L with state −s_0, one sequence at a time.
  for (std::int64_t b = 0; b < 3; ++b) {
    for (double sign : {1.0, -1.0}) {
      SequenceChain& chain = net.forward_chain();
      auto state = chain.initial_state(torch::full({1}, sign));
      torch::Tensor x = (sign > 0 ? w.front() : w.back()).narrow(0, b, 1);
      for (int i = 1; i < 5; ++i) {
        x = x + chain.step(x, state);
        const torch::Tensor& got = (sign > 0 ? r.forward : r.backward)[static_cast<std::size_t>(i)];
        EXPECT_TRUE(torch::allclose(got.narrow(0, b, 1), x, 1e-5, 1e-6)) << b << " " << sign << " " << i;
      }
    }
  }
  // The initial state's sign matters: the two chains from the same frame differ.
  auto plus = net.forward_chain().initial_state(torch::ones({1}));
  auto minus = net.forward_chain().initial_state(-torch::ones({1}));
  const torch::Tensor x = w.front().narrow(0, 0, 1);
  EXPECT_FALSE(torch::allclose(net.forward_chain().step(x, plus), net.forward_chain().step(x, minus)));
}

TEST(SequenceNet, GenerationFeedsTheInitialFramesInOrder) {
  torch::manual_seed(0);
  SequenceNet net(small("shared"), kV, ring_edges());
  net.eval();
  torch::NoGradGuard no_grad;
  const auto w = window(1, 3);
  const auto one = net.generate({w[2]}, 4);
  const auto three = net.generate(w, 4);
  ASSERT_EQ(one.size(), 4u);
  ASSERT_EQ(three.size(), 4u);
  // The first generated frame is X_u + δX; with 3 frames the state has seen X_1, X_2 first.
  auto state = net.forward_chain().initial_state(torch::ones({1}));
  EXPECT_TRUE(torch::allclose(one[0], w[2] + net.forward_chain().step(w[2], state)));
  EXPECT_FALSE(torch::allclose(one[0], three[0]));
  state = net.forward_chain().initial_state(torch::ones({1}));
  net.forward_chain().step(w[0], state);
  net.forward_chain().step(w[1], state);
  torch::Tensor x = w[2] + net.forward_chain().step(w[2], state);
  EXPECT_TRUE(torch::allclose(three[0], x));
  x = x + net.forward_chain().step(x, state);
  EXPECT_TRUE(torch::allclose(three[1], x, 1e-5, 1e-6));
  // In training mode z is sampled: two runs differ.
  net.train();
  EXPECT_FALSE(torch::allclose(net.generate({w[2]}, 2)[1], net.generate({w[2]}, 2)[1]));
}

TEST(SequenceNet, ObjectiveOfEquations3To5) {
  torch::manual_seed(0);
  SequenceNet net(small("shared"), kV, ring_edges());
  const auto w = window(2, 4);
  double l2 = 0;
  for (const auto& p : net.parameters()) l2 += p.pow(2).sum().item<double>();
  Rollout perfect;
  perfect.forward = w;
  perfect.backward = {w.rbegin(), w.rend()};
  perfect.kl = torch::tensor(2.0);
  std::map<std::string, double> parts;
  const Objective o{1.0, 0.5, 0.1, 0.1};
  const double total = sequence_loss(net, perfect, w, o, &parts).item<double>();
  EXPECT_NEAR(parts["recon"], 0, 1e-9);
  EXPECT_NEAR(parts["bidir"], 0, 1e-9);
  EXPECT_NEAR(parts["l2"], l2, 1e-3 * l2);
  EXPECT_NEAR(total, 0.1 * 2.0 + 0.1 * l2, 1e-3);
  // One wrong forward frame: its Frobenius distance (batch mean) in L_recon and again in L_bidir.
  Rollout off = perfect;
  off.forward[2] = w[2] + 0.5;  // every entry off by 0.5: ‖·‖ = 0.5 √(6·9) per sequence
  parts.clear();
  sequence_loss(net, off, w, o, &parts);
  EXPECT_NEAR(parts["recon"], 0.5 * std::sqrt(54.0), 1e-4);
  EXPECT_NEAR(parts["bidir"], 0.5 * std::sqrt(54.0), 1e-4);
  // Unidirectional: no backward terms.
  Rollout forward_only = off;
  forward_only.backward.clear();
  parts.clear();
  sequence_loss(net, forward_only, w, o, &parts);
  EXPECT_NEAR(parts["recon"], 0.5 * std::sqrt(54.0), 1e-4);
  EXPECT_EQ(parts["bidir"], 0);
}

TEST(SequenceNet, OptionsAndErrors) {
  const auto parse = [](const std::string& yaml) {
    return SequenceNetOptions::from(config::Config::parse(yaml, "model.yaml").root());
  };
  const SequenceNetOptions o = parse("{type: bdlstm}");
  EXPECT_EQ(o.conv, (std::vector<std::int64_t>{9, 9, 9}));
  EXPECT_EQ(o.hidden, 128);
  EXPECT_EQ(o.lstm_layers, 3);
  EXPECT_EQ(o.initial_state, 0.1);
  expect_error<ConfigError>([&] { parse("{type: bdlstm, scheme: sideways}"); },
                            {"model.yaml", "scheme", "shared, standard, unidirectional"});
  expect_error<ConfigError>([&] { parse("{type: bdlstm, conv: []}"); }, {"conv"});
  expect_error<ConfigError>([&] { parse("{type: densegats}"); }, {"bdlstm"});
  expect_error<ConfigError>([&] { parse("{type: bdlstm, hiden: 3}"); }, {"hiden"});
  SequenceNet net(small("shared"), kV, ring_edges());
  EXPECT_THROW(net.forward_chain().encode(torch::zeros({1, kV + 1, 9})), c10::Error);
  EXPECT_THROW(net.rollout({torch::zeros({1, kV, 9})}), c10::Error);
}

TEST(SequenceConfig, OneMeshPerNetworkAndOneMethod) {
  const auto load = [](const std::vector<std::string>& overrides) {
    return SequenceConfig::from(config::Config::load(
        std::string(SKINLAB_SOURCE_DIR) + "/configs/bdlstm/bdlstm.yaml", overrides));
  };
  const SequenceConfig c = load({});
  EXPECT_EQ(c.sequences.window, 32);
  EXPECT_EQ(c.sequences.batch, 8);
  EXPECT_EQ(c.sequences.objective.bidir, 0.5);
  EXPECT_EQ(c.sequences.data.characters, std::vector<std::string>{"horse"});
  expect_error<ConfigError>([&] { load({"sequences.characters=[horse, wolf]"}); },
                            {"task.yaml", "sequences", "one name"});
  expect_error<ConfigError>([&] { load({"sequences.baseline=hold"}); }, {"not both"});
  expect_error<ConfigError>([&] { load({"sequences.baseline=spline"}); }, {"acap_extrapolation"});
  expect_error<ConfigError>([&] { load({"sequences.objective.kl=-1"}); }, {"kl", "≥ 0"});
  expect_error<ConfigError>([&] { load({"sequences.initial_frames=[4]"}); }, {"initial_frames"});
  expect_error<ConfigError>([&] { load({"sequences.windw=3"}); }, {"windw"});
  expect_error<ConfigError>([&] { load({"task=skinning"}); }, {"sequences"});
}

// The chain's layers keep the names and order they had before the encoder and decoder became
// a MeshCodec shared with the mesh VAE, so saved checkpoints and seeded initialisations hold.
TEST(SequenceNet, ChainParametersAreNamedAndOrderedAsBefore) {
  SequenceNet net(small("shared"), kV, ring_edges());
  std::vector<std::string> layers;
  for (const auto& item : net.named_parameters()) {
    const std::string name = item.key();
    const std::string layer = name.substr(0, name.find('.', name.find('.') + 1));
    if (layers.empty() || layers.back() != layer) layers.push_back(layer);
  }
  EXPECT_EQ(layers, (std::vector<std::string>{"forward_chain.conv0", "forward_chain.conv1",
                                              "forward_chain.posterior", "forward_chain.cell",
                                              "forward_chain.expand", "forward_chain.tconv0",
                                              "forward_chain.tconv1"}));
}

// [4]'s extrapolation: a mesh VAE continued from two equal frames stays at the last frame's
// reconstruction (zero latent velocity); otherwise frame h decodes z_l + h (z_l − z_{l−1}), so
// the latent steps between consecutive extrapolated frames are all the same.
TEST(MeshVae, ExtrapolatesLinearlyInItsLatentSpace) {
  MeshVaeOptions o;
  o.conv = {5, 4};
  o.latent = 6;
  torch::manual_seed(1);
  MeshVae vae(o, kV, ring_edges());
  vae.eval();
  torch::NoGradGuard no_grad;
  const auto w = window(2, 2);
  const auto still = vae.extrapolate(w[1], w[1], 3);
  ASSERT_EQ(still.size(), 3u);
  for (const auto& x : still) EXPECT_TRUE(torch::allclose(x, vae.reconstruct(w[1]), 1e-5, 1e-6));
  const auto moving = vae.extrapolate(w[0], w[1], 3);
  const torch::Tensor z0 = vae.encode(w[0]).first, z1 = vae.encode(w[1]).first;
  for (int h = 1; h <= 3; ++h) {
    EXPECT_TRUE(torch::allclose(moving[h - 1], vae.decode(z1 + h * (z1 - z0)), 1e-5, 1e-6)) << h;
  }
  EXPECT_FALSE(torch::allclose(moving[0], moving[2]));
  // Training mode samples z; evaluation uses μ.
  vae.train();
  torch::Tensor kl;
  EXPECT_FALSE(torch::equal(vae.reconstruct(w[1], &kl), vae.reconstruct(w[1])));
  EXPECT_GT(kl.item<double>(), 0);
  expect_error<ConfigError>(
      [] { MeshVaeOptions::from(config::Config::parse("{type: mesh_vae, hidden: 3}", "v.yaml").root()); },
      {"v.yaml", "hidden"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::bdlstm

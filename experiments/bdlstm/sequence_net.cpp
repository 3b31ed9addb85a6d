#include "experiments/bdlstm/sequence_net.hpp"

#include <fmt/format.h>

#include "framework/geometry/acap.hpp"

namespace skinlab::bdlstm {

SequenceNetOptions SequenceNetOptions::from(const config::Node& node) {
  SequenceNetOptions o;
  config::Fields f(node, "model 'bdlstm'");
  std::string type;
  f.required("type", type).check(type == "bdlstm", "type",
                                 "the sequence task's network is 'bdlstm' (experiments/bdlstm)");
  f.optional("conv", o.conv);
  graph::check_widths(f, "conv", o.conv, false);
  f.optional("latent", o.latent).check(o.latent >= 1, "latent", "must be ≥ 1");
  f.optional("lstm_layers", o.lstm_layers).check(o.lstm_layers >= 1, "lstm_layers", "must be ≥ 1");
  f.optional("hidden", o.hidden).check(o.hidden >= 1, "hidden", "must be ≥ 1");
  f.optional("initial_state", o.initial_state);
  f.optional("scheme", o.scheme)
      .check(o.scheme == "shared" || o.scheme == "standard" || o.scheme == "unidirectional",
             "scheme", "unknown scheme '" + o.scheme + "'; known: shared, standard, unidirectional");
  f.finish();
  return o;
}

namespace {

std::shared_ptr<graph::MeanConv> conv_layer(std::int64_t in, std::int64_t width, bool tanh,
                                            bool transpose) {
  graph::MeanConv::Options o;
  o.width = width;
  o.tanh = tanh;
  o.transpose = transpose;
  auto op = std::make_shared<graph::MeanConv>(o);
  op->build({in, 0, 0});
  return op;
}

}  // namespace

SequenceChain::SequenceChain(const SequenceNetOptions& options, std::int64_t num_vertices)
    : options_(options), num_vertices_(num_vertices) {
  TORCH_CHECK(num_vertices >= 1, "bdlstm: a mesh needs vertices");
  const std::int64_t C = options_.conv.back();
  std::int64_t in = geometry::kAcapWidth;
  for (std::size_t i = 0; i < options_.conv.size(); ++i) {
    encoder_.push_back(register_module(fmt::format("conv{}", i),
                                       conv_layer(in, options_.conv[i], true, false)));
    in = options_.conv[i];
  }
  posterior_ = register_module("posterior", torch::nn::Linear(num_vertices * C, 2 * options_.latent));
  cell_ = register_module(
      "cell", torch::nn::LSTM(torch::nn::LSTMOptions(options_.latent, options_.hidden)
                                  .num_layers(options_.lstm_layers)));
  expand_ = register_module("expand", torch::nn::Linear(options_.hidden, num_vertices * C));
  // tCnv mirrors Conv: C → conv[n−2] → ... → conv[0] → 9, the last layer linear.
  std::vector<std::int64_t> widths(options_.conv.rbegin() + 1, options_.conv.rend());
  widths.push_back(geometry::kAcapWidth);
  in = C;
  for (std::size_t i = 0; i < widths.size(); ++i) {
    const bool last = i + 1 == widths.size();
    decoder_.push_back(register_module(fmt::format("tconv{}", i),
                                       conv_layer(in, widths[i], !last, true)));
    in = widths[i];
  }
}

torch::Tensor SequenceChain::convolve(std::vector<std::shared_ptr<graph::MeanConv>>& layers,
                                      torch::Tensor x, const torch::Tensor& op) {
  TORCH_CHECK(op.defined(), "bdlstm: the chain has no mesh edges");
  const std::int64_t B = x.size(0), V = x.size(1);
  for (auto& layer : layers) {
    const std::int64_t C = x.size(2);
    const torch::Tensor side_by_side = x.permute({1, 0, 2}).reshape({V, B * C});
    const torch::Tensor aggregated = torch::mm(op, side_by_side).view({V, B, C}).permute({1, 0, 2});
    x = layer->combine(x.reshape({B * V, C}), aggregated.reshape({B * V, C})).view({B, V, -1});
  }
  return x;
}

std::pair<torch::Tensor, torch::Tensor> SequenceChain::encode(const torch::Tensor& frames) {
  TORCH_CHECK(frames.dim() == 3 && frames.size(1) == num_vertices_ &&
                  frames.size(2) == geometry::kAcapWidth,
              "bdlstm: expected B×", num_vertices_, "×", geometry::kAcapWidth,
              " ACAP features, got ", frames.sizes());
  const std::int64_t B = frames.size(0);
  const torch::Tensor x = convolve(encoder_, frames, mean_);
  const torch::Tensor out = posterior_->forward(x.reshape({B, -1}));
  return {out.narrow(1, 0, options_.latent), out.narrow(1, options_.latent, options_.latent)};
}

torch::Tensor SequenceChain::step(const torch::Tensor& frames, State& state, torch::Tensor* kl) {
  const std::int64_t B = frames.size(0);
  auto [mu, logvar] = encode(frames);
  torch::Tensor z = mu;
  if (is_training()) z = mu + torch::exp(0.5 * logvar) * torch::randn_like(mu);
  if (kl) {
    // D_KL(N(μ, σ²) ‖ N(0, I)) = ½ Σ (μ² + σ² − 1 − log σ²) (Kingma and Welling, App. B).
    *kl = *kl + 0.5 * (mu.pow(2) + logvar.exp() - 1 - logvar).sum(1).mean();
  }
  auto [out, next] = cell_->forward(z.unsqueeze(0), std::make_tuple(state.h, state.c));
  state.h = std::get<0>(next);
  state.c = std::get<1>(next);
  const std::int64_t C = options_.conv.back();
  const torch::Tensor expanded = torch::tanh(expand_->forward(out.squeeze(0)));
  return convolve(decoder_, expanded.reshape({B, num_vertices_, C}), mean_transpose_);
}

SequenceChain::State SequenceChain::initial_state(const torch::Tensor& signs) const {
  const torch::Tensor s0 = (signs.to(torch::kFloat32) * options_.initial_state)
                               .view({1, -1, 1})
                               .expand({options_.lstm_layers, signs.size(0), options_.hidden})
                               .contiguous();
  return {s0, s0.clone()};
}

SequenceNet::SequenceNet(const SequenceNetOptions& options, std::int64_t num_vertices,
                         torch::Tensor one_ring)
    : options_(options) {
  TORCH_CHECK(one_ring.dim() == 2 && one_ring.size(1) == 2 && one_ring.scalar_type() == torch::kInt64,
              "bdlstm: the mesh edges must be #E×2 int64, got ", one_ring.sizes());
  forward_ = register_module("forward_chain", std::make_shared<SequenceChain>(options_, num_vertices));
  const torch::Tensor mean = graph::mean_operator(one_ring, num_vertices, false);
  const torch::Tensor transpose = graph::mean_operator(one_ring, num_vertices, true);
  forward_->mean_ = mean;
  forward_->mean_transpose_ = transpose;
  if (options_.scheme == "standard") {
    backward_ = register_module("backward_chain", std::make_shared<SequenceChain>(options_, num_vertices));
    backward_->mean_ = mean;
    backward_->mean_transpose_ = transpose;
  }
}

std::vector<torch::Tensor> SequenceNet::run(SequenceChain& chain, const std::vector<torch::Tensor>& initial,
                                            int count, const torch::Tensor& signs, torch::Tensor* kl,
                                            int* steps) {
  TORCH_CHECK(!initial.empty(), "bdlstm: a chain needs at least one initial frame");
  SequenceChain::State state = chain.initial_state(signs);
  std::vector<torch::Tensor> generated;
  torch::Tensor x;
  for (std::size_t k = 0; k < initial.size(); ++k) {
    x = initial[k] + chain.step(initial[k], state, kl);
    if (steps) ++*steps;
  }
  for (int n = 0; n < count; ++n) {
    generated.push_back(x);
    if (n + 1 == count) break;
    x = x + chain.step(x, state, kl);
    if (steps) ++*steps;
  }
  return generated;
}

Rollout SequenceNet::rollout(const std::vector<torch::Tensor>& window) {
  TORCH_CHECK(window.size() >= 2, "bdlstm: a training window needs at least 2 frames, got ",
              window.size());
  const int L = static_cast<int>(window.size());
  const std::int64_t B = window.front().size(0);
  const torch::Tensor plus = torch::ones({B}), minus = -torch::ones({B});
  Rollout r;
  torch::Tensor kl = torch::zeros({});
  int steps = 0;
  r.forward = {window.front()};
  if (options_.scheme == "shared") {
    // One batch of 2B: the forward chains from X_1 (+s_0), the backward chains from X_L (−s_0).
    r.backward = {window.back()};
    const auto both = run(*forward_, {torch::cat({window.front(), window.back()})}, L - 1,
                          torch::cat({plus, minus}), &kl, &steps);
    for (const auto& x : both) {
      r.forward.push_back(x.narrow(0, 0, B));
      r.backward.push_back(x.narrow(0, B, B));
    }
  } else {
    for (auto& x : run(*forward_, {window.front()}, L - 1, plus, &kl, &steps)) r.forward.push_back(x);
    if (bidirectional()) {
      r.backward = {window.back()};
      for (auto& x : run(*backward_, {window.back()}, L - 1, minus, &kl, &steps)) r.backward.push_back(x);
    }
  }
  r.kl = kl / static_cast<double>(steps);  // each step adds its batch mean: a mean per frame
  return r;
}

std::vector<torch::Tensor> SequenceNet::generate(const std::vector<torch::Tensor>& initial, int count) {
  return run(*forward_, initial, count, torch::ones({initial.front().size(0)}), nullptr, nullptr);
}

}  // namespace skinlab::bdlstm

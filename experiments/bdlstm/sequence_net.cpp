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

MeshCodec::MeshCodec(std::vector<std::int64_t> conv, std::int64_t latent, std::int64_t num_vertices,
                     torch::Tensor one_ring)
    : conv_(std::move(conv)), latent_(latent), num_vertices_(num_vertices) {
  TORCH_CHECK(num_vertices >= 1, "bdlstm: a mesh needs vertices");
  TORCH_CHECK(one_ring.dim() == 2 && one_ring.size(1) == 2 && one_ring.scalar_type() == torch::kInt64,
              "bdlstm: the mesh edges must be #E×2 int64, got ", one_ring.sizes());
  mean_ = graph::mean_operator(one_ring, num_vertices, false);
  mean_transpose_ = graph::mean_operator(one_ring, num_vertices, true);
}

void MeshCodec::register_encoder(torch::nn::Module& owner) {
  std::int64_t in = geometry::kAcapWidth;
  for (std::size_t i = 0; i < conv_.size(); ++i) {
    encoder_.push_back(owner.register_module(fmt::format("conv{}", i), conv_layer(in, conv_[i], true, false)));
    in = conv_[i];
  }
  posterior_ = owner.register_module("posterior", torch::nn::Linear(num_vertices_ * conv_.back(), 2 * latent_));
}

void MeshCodec::register_decoder(torch::nn::Module& owner, std::int64_t code_width) {
  const std::int64_t C = conv_.back();
  expand_ = owner.register_module("expand", torch::nn::Linear(code_width, num_vertices_ * C));
  // tCnv mirrors Conv: C → conv[n−2] → ... → conv[0] → 9, the last layer linear.
  std::vector<std::int64_t> widths(conv_.rbegin() + 1, conv_.rend());
  widths.push_back(geometry::kAcapWidth);
  std::int64_t in = C;
  for (std::size_t i = 0; i < widths.size(); ++i) {
    const bool last = i + 1 == widths.size();
    decoder_.push_back(owner.register_module(fmt::format("tconv{}", i), conv_layer(in, widths[i], !last, true)));
    in = widths[i];
  }
}

torch::Tensor MeshCodec::convolve(std::vector<std::shared_ptr<graph::MeanConv>>& layers, torch::Tensor x,
                                  const torch::Tensor& op) {
  const std::int64_t B = x.size(0), V = x.size(1);
  for (auto& layer : layers) {
    const std::int64_t C = x.size(2);
    const torch::Tensor side_by_side = x.permute({1, 0, 2}).reshape({V, B * C});
    const torch::Tensor aggregated = torch::mm(op, side_by_side).view({V, B, C}).permute({1, 0, 2});
    x = layer->combine(x.reshape({B * V, C}), aggregated.reshape({B * V, C})).view({B, V, -1});
  }
  return x;
}

std::pair<torch::Tensor, torch::Tensor> MeshCodec::encode(const torch::Tensor& frames) {
  TORCH_CHECK(frames.dim() == 3 && frames.size(1) == num_vertices_ &&
                  frames.size(2) == geometry::kAcapWidth,
              "bdlstm: expected B×", num_vertices_, "×", geometry::kAcapWidth,
              " ACAP features, got ", frames.sizes());
  const std::int64_t B = frames.size(0);
  const torch::Tensor x = convolve(encoder_, frames, mean_);
  const torch::Tensor out = posterior_->forward(x.reshape({B, -1}));
  return {out.narrow(1, 0, latent_), out.narrow(1, latent_, latent_)};
}

torch::Tensor MeshCodec::decode(const torch::Tensor& code) {
  const torch::Tensor expanded = torch::tanh(expand_->forward(code));
  return convolve(decoder_, expanded.reshape({code.size(0), num_vertices_, conv_.back()}), mean_transpose_);
}

torch::Tensor kl_divergence(const torch::Tensor& mu, const torch::Tensor& logvar) {
  // D_KL(N(μ, σ²) ‖ N(0, I)) = ½ Σ (μ² + σ² − 1 − log σ²) (Kingma and Welling, App. B).
  return 0.5 * (mu.pow(2) + logvar.exp() - 1 - logvar).sum(1).mean();
}

SequenceChain::SequenceChain(const SequenceNetOptions& options, std::int64_t num_vertices,
                             torch::Tensor one_ring)
    : options_(options), codec_(options.conv, options.latent, num_vertices, std::move(one_ring)) {
  codec_.register_encoder(*this);
  cell_ = register_module(
      "cell", torch::nn::LSTM(torch::nn::LSTMOptions(options_.latent, options_.hidden)
                                  .num_layers(options_.lstm_layers)));
  codec_.register_decoder(*this, options_.hidden);
}

torch::Tensor SequenceChain::step(const torch::Tensor& frames, State& state, torch::Tensor* kl) {
  auto [mu, logvar] = encode(frames);
  torch::Tensor z = mu;
  if (is_training()) z = mu + torch::exp(0.5 * logvar) * torch::randn_like(mu);
  if (kl) *kl = *kl + kl_divergence(mu, logvar);
  auto [out, next] = cell_->forward(z.unsqueeze(0), std::make_tuple(state.h, state.c));
  state.h = std::get<0>(next);
  state.c = std::get<1>(next);
  return codec_.decode(out.squeeze(0));
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
  forward_ = register_module("forward_chain", std::make_shared<SequenceChain>(options_, num_vertices, one_ring));
  if (options_.scheme == "standard") {
    backward_ = register_module("backward_chain",
                                std::make_shared<SequenceChain>(options_, num_vertices, one_ring));
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

std::string sequence_model_type(const config::Node& node) {
  std::string type;
  config::Fields f(node, "model", {});
  f.required("type", type).check(type == "bdlstm" || type == "mesh_vae", "type",
                                 "the sequence task's networks are 'bdlstm' and 'mesh_vae' "
                                 "(experiments/bdlstm)");
  return type;
}

MeshVaeOptions MeshVaeOptions::from(const config::Node& node) {
  MeshVaeOptions o;
  config::Fields f(node, "model 'mesh_vae'");
  std::string type;
  f.required("type", type).check(type == "mesh_vae", "type", "expected 'mesh_vae'");
  f.optional("conv", o.conv);
  graph::check_widths(f, "conv", o.conv, false);
  f.optional("latent", o.latent).check(o.latent >= 1, "latent", "must be ≥ 1");
  f.finish();
  return o;
}

MeshVae::MeshVae(const MeshVaeOptions& options, std::int64_t num_vertices, torch::Tensor one_ring)
    : codec_(options.conv, options.latent, num_vertices, std::move(one_ring)) {
  codec_.register_encoder(*this);
  codec_.register_decoder(*this, options.latent);
}

torch::Tensor MeshVae::reconstruct(const torch::Tensor& frames, torch::Tensor* kl) {
  auto [mu, logvar] = encode(frames);
  torch::Tensor z = mu;
  if (is_training()) z = mu + torch::exp(0.5 * logvar) * torch::randn_like(mu);
  if (kl) *kl = kl_divergence(mu, logvar);
  return decode(z);
}

std::vector<torch::Tensor> MeshVae::extrapolate(const torch::Tensor& previous, const torch::Tensor& last,
                                                int count) {
  const torch::Tensor z_previous = encode(previous).first, z_last = encode(last).first;
  std::vector<torch::Tensor> out;
  for (int h = 1; h <= count; ++h) out.push_back(decode(z_last + h * (z_last - z_previous)));
  return out;
}

}  // namespace skinlab::bdlstm

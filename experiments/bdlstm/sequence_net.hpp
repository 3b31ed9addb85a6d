#pragma once
/// \file
/// The generative network of the mesh-sequence BiLSTM (Qiao et al., "Synthesizing Mesh
/// Deformation Sequences with Bidirectional LSTM", Sec. 3.2-3.3, Fig. 1), for one mesh.
///
/// One step (Sec. 3.2), from the ACAP features X_t (#V×9, scaled into [−0.95, 0.95]) and the
/// LSTM state s_t:
///
///     Conv:  3 mean_conv layers (Eq. 2, tanh; graph/mean_conv.hpp) → flatten #V·C →
///            fully connected → μ, log σ² (the VAE posterior q(z|X) of Sec. 3.4's L_KL);
///            z = μ + σ ε in training (reparameterised), z = μ otherwise
///     cell:  a 3-layer LSTM, 128 hidden: (z', s_{t+1}) = cell(z, s_t)
///     tCnv:  fully connected → tanh → #V×C → transposed mean_convs (tanh; the last linear) → δX_t
///     X_{t+1} = X_t + δX_t
///
/// A chain is started from its initial frames with the initial state s_0 = ±[0.1]: every
/// initial frame is put through the step in order (updating the state), the last one's output
/// is the first generated frame, and each generated frame is the next input (Sec. 3.2,
/// "Our method first puts the existing models into the network in their order ...").
///
/// The fully connected layers are sized by the mesh, so a network belongs to one mesh (as the
/// paper's: one network per data set of one connectivity).
///
/// Schemes (`model.scheme`; Sec. 3.3 and Table 2):
///  - `shared` (the paper's): the forward chain (s_0^f = +0.1) and the backward chain
///    (s_0^b = −0.1) run the same Conv, cell and tCnv: one parameter set.
///  - `standard` ("Std. BD-LSTM"): the backward chain has its own copy of everything, so twice
///    the parameters ("weight-sharing ... halves the trainable parameters").
///  - `unidirectional` ("Unidir. LSTM"): the forward chain only.
///
///     model:
///       type: bdlstm
///       conv: [9, 9, 9]        # encoder mean_conv widths (Sec. 4.1: 3 layers, tanh)
///       latent: 128            # z
///       lstm_layers: 3         # Sec. 4.1
///       hidden: 128            # Sec. 4.1
///       initial_state: 0.1     # s_0^f = −s_0^b = [0.1]^128 (h and c of every layer)
///       scheme: shared         # shared | standard | unidirectional

#include <torch/torch.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/graph/mean_conv.hpp"

namespace skinlab::bdlstm {

struct SequenceNetOptions {
  std::vector<std::int64_t> conv{9, 9, 9};
  std::int64_t latent = 128;
  std::int64_t lstm_layers = 3;
  std::int64_t hidden = 128;
  double initial_state = 0.1;
  std::string scheme = "shared";
  /// Decodes the `model:` node (`type: bdlstm`); errors name the file, line and key.
  static SequenceNetOptions from(const config::Node& node);
};

/// The Conv and tCnv halves of a step (Sec. 3.2), shared by the chain and the mesh VAE: the
/// encoder's mean_convs (tanh) and the fully connected layer to μ, log σ²; the fully connected
/// layer from a code to #V·C (tanh) and the transposed mean_convs (tanh, the last linear). Its
/// layers are registered on the owning module as conv<i>, posterior, expand and tconv<i>, the
/// encoder's and the decoder's in two calls so the owner can register its own layers between.
class MeshCodec {
 public:
  MeshCodec(std::vector<std::int64_t> conv, std::int64_t latent, std::int64_t num_vertices,
            torch::Tensor one_ring);
  void register_encoder(torch::nn::Module& owner);
  /// `code_width`: the width of what `decode` is given (the LSTM's output, or z).
  void register_decoder(torch::nn::Module& owner, std::int64_t code_width);

  /// The posterior of B frames (B×V×9): μ and log σ², each B×latent.
  std::pair<torch::Tensor, torch::Tensor> encode(const torch::Tensor& frames);
  /// B×V×9 from B codes (B×code_width).
  torch::Tensor decode(const torch::Tensor& code);
  std::int64_t num_vertices() const { return num_vertices_; }
  std::int64_t latent() const { return latent_; }

 private:
  /// The mean_convs of `layers` on B×V×C frames: each layer's neighbour term is one sparse
  /// product with the mesh's A (or Aᵀ) over all B frames side by side.
  static torch::Tensor convolve(std::vector<std::shared_ptr<graph::MeanConv>>& layers,
                                torch::Tensor x, const torch::Tensor& op);

  std::vector<std::int64_t> conv_;
  std::int64_t latent_, num_vertices_;
  torch::Tensor mean_, mean_transpose_;  ///< A and Aᵀ of Eq. 2 (graph::mean_operator)
  std::vector<std::shared_ptr<graph::MeanConv>> encoder_, decoder_;
  torch::nn::Linear posterior_{nullptr}, expand_{nullptr};
};

/// D_KL(N(μ, σ²) ‖ N(0, I)) summed over the latent dimensions, averaged over the batch.
torch::Tensor kl_divergence(const torch::Tensor& mu, const torch::Tensor& logvar);

/// The Conv → cell → tCnv step of one chain, over a batch of B frames of one mesh.
class SequenceChain : public torch::nn::Module {
 public:
  SequenceChain(const SequenceNetOptions& options, std::int64_t num_vertices, torch::Tensor one_ring);

  struct State {
    torch::Tensor h, c;  ///< layers × B × hidden
  };
  /// The encoder's posterior of B frames (B×V×9): μ and log σ², each B×latent.
  std::pair<torch::Tensor, torch::Tensor> encode(const torch::Tensor& frames) { return codec_.encode(frames); }
  /// One step: δX (B×V×9) from frames X_t (B×V×9) and `state` (updated). In training mode z is
  /// sampled with libtorch's default generator; the step's KL divergence to N(0, I), summed over
  /// the latent dimensions and averaged over the batch, is added to `*kl` when given.
  torch::Tensor step(const torch::Tensor& frames, State& state, torch::Tensor* kl = nullptr);
  /// s_0 = sign_b · initial_state for every sequence b of the batch (`signs`: B values ±1).
  State initial_state(const torch::Tensor& signs) const;

  std::int64_t num_vertices() const { return codec_.num_vertices(); }

 private:
  SequenceNetOptions options_;
  MeshCodec codec_;
  torch::nn::LSTM cell_{nullptr};
};

/// What a pair of chains produced for a batch of training windows of L frames.
struct Rollout {
  std::vector<torch::Tensor> forward;   ///< S^f_1..S^f_L (S^f_1 = X_1), each B×V×9
  std::vector<torch::Tensor> backward;  ///< S^b_1..S^b_L (S^b_1 = X_L); empty for unidirectional
  torch::Tensor kl;                     ///< mean over the encoded frames (scalar)
};

class SequenceNet : public torch::nn::Module {
 public:
  /// `one_ring`: the mesh's #E×2 int64 edges (both directions), the mean_conv neighbourhoods.
  SequenceNet(const SequenceNetOptions& options, std::int64_t num_vertices, torch::Tensor one_ring);

  const SequenceNetOptions& options() const { return options_; }
  bool bidirectional() const { return options_.scheme != "unidirectional"; }
  /// The forward chain, and the backward chain (the same object under `shared`).
  SequenceChain& forward_chain() { return *forward_; }
  SequenceChain& backward_chain() { return backward_ ? *backward_ : *forward_; }

  /// Training (Sec. 3.3): for windows X_1..X_L (L × [B×V×9]), the forward chain from X_1 and
  /// the backward chain from X_L, each generating L − 1 frames free-running. Under `shared` the
  /// two chains run as one batch of 2B (the same weights; the states differ by sign).
  Rollout rollout(const std::vector<torch::Tensor>& window);

  /// Generation with the forward chain (Sec. 3.2, Table 1): the `initial` frames (u × [B×V×9])
  /// are put through the chain in order, then `count` frames are generated; returns them.
  std::vector<torch::Tensor> generate(const std::vector<torch::Tensor>& initial, int count);

 private:
  /// Runs `chain` from `initial` (teacher inputs) for `count` generated frames, sequence b
  /// starting from the state signs[b] · s_0. Adds each step's KL to `kl` and counts the steps.
  static std::vector<torch::Tensor> run(SequenceChain& chain, const std::vector<torch::Tensor>& initial,
                                        int count, const torch::Tensor& signs, torch::Tensor* kl,
                                        int* steps);

  SequenceNetOptions options_;
  std::shared_ptr<SequenceChain> forward_, backward_;
};

/// The mesh VAE of Table 1's "[4]" row (Tan et al., "Variational Autoencoders for Deforming
/// 3D Mesh Models", CVPR 2018): a frame's features are encoded to a latent z and decoded back,
/// with no temporal model; a sequence is continued by extrapolating linearly in its latent space
/// from two initial frames, z_{l+h} = z_l + h (z_l − z_{l−1}) (Sec. 4.2, Fig. 5 (c)). Tan et al.
/// use fully connected layers on their RIMD features; ours encodes and decodes with the same
/// Conv and tCnv as the BiLSTM (MeshCodec) on the same ACAP features, so the Table 1 rows differ
/// in the temporal model only.
///
///     model:
///       type: mesh_vae
///       conv: [9, 9, 9]
///       latent: 128
struct MeshVaeOptions {
  std::vector<std::int64_t> conv{9, 9, 9};
  std::int64_t latent = 128;
  static MeshVaeOptions from(const config::Node& node);
};

class MeshVae : public torch::nn::Module {
 public:
  MeshVae(const MeshVaeOptions& options, std::int64_t num_vertices, torch::Tensor one_ring);
  /// μ and log σ² of B frames (B×V×9).
  std::pair<torch::Tensor, torch::Tensor> encode(const torch::Tensor& frames) { return codec_.encode(frames); }
  torch::Tensor decode(const torch::Tensor& z) { return codec_.decode(z); }
  /// Reconstructions of B frames (z sampled in training mode, μ otherwise) and, when given,
  /// the batch's KL divergence in `*kl`.
  torch::Tensor reconstruct(const torch::Tensor& frames, torch::Tensor* kl = nullptr);
  /// The frames h = 1..count after `last`, decoded from z_last + h (z_last − z_previous) (μ's).
  std::vector<torch::Tensor> extrapolate(const torch::Tensor& previous, const torch::Tensor& last,
                                         int count);

 private:
  MeshCodec codec_;
};

/// `bdlstm` or `mesh_vae`: the `type` of a sequence task's `model:` node (ConfigError naming the
/// file and line for anything else).
std::string sequence_model_type(const config::Node& node);

}  // namespace skinlab::bdlstm

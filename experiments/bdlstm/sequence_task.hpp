#pragma once
/// \file
/// Training, evaluation and generation of the mesh-sequence task (`task: sequence`; Qiao et al.,
/// "Synthesizing Mesh Deformation Sequences with Bidirectional LSTM"), on the sequences of
/// sequence_data.hpp with the network of sequence_net.hpp.
///
///     task: sequence
///     data: {file: results/datasets/zeroad_sequences.h5}   # or sequences.folder (OBJ sequences)
///     sequences:                 # sequence_data.hpp's keys (characters, frame_stride, ...), and
///       window: 32               # frames per training sequence (Sec. 4.1: 32)
///       batch: 8                 # training sequences per iteration (Sec. 4.1: 8)
///       iterations_per_epoch: 100
///       objective: {recon: 1.0, bidir: 0.5, kl: 0.1, l2: 0.1}   # Eq. 3: α1 = 0.5, α2 = 0.1
///       initial_frames: [1, 3]   # Table 1: Ours+1 IF, Ours+3 IF
///       horizons: [5, 10, 15]    # Table 1: the 5th, 10th, 15th generated frame
///       baseline: ""             # or acap_extrapolation ([24]) / hold, instead of a model
///
/// Features are scaled into [−0.95, 0.95] per (vertex, dimension) over the character's frames
/// outside its test windows (acap.hpp's FeatureScale): the training and validation frames, so
/// that the scale, and with it every trained run, does not depend on val_fraction. The network
/// sees and predicts scaled features.
///
/// Training (Sec. 3.3-3.4, 4.1): each iteration draws `batch` windows of `window` consecutive
/// training frames (never crossing a test or validation window; shorter when no training
/// stretch is that long), runs the forward chain from each window's first frame and the
/// backward chain from its last, free-running, and minimises Eq. 3:
///
///     L = recon · L_recon + bidir · L_bidir + kl · L_KL + l2 · L_2
///     L_recon = Σ_{i=2..L} ‖S^f_i − X_i‖ + ‖S^b_i − X_{L+1−i}‖                   (Eq. 4)
///     L_bidir = Σ_{i=1..L} ‖S^f_i − S^b_{L+1−i}‖                                  (Eq. 5)
///
/// ‖·‖ is the Frobenius norm of a frame's #V×9 feature difference (the paper's norm, not
/// squared), averaged over the batch; the i = 1 terms of Eq. 4 are the given frames and vanish.
/// L_KL is the VAE term of Sec. 3.4, averaged over the encoded frames; L_2 = Σ w² over every
/// trainable parameter. The paper's α2 = 0.1 weighs L_KL + L_2, so both weights are 0.1 here;
/// "w/o L_KL" (Table 2) sets kl: 0. The unidirectional scheme has no backward chain, so no
/// backward reconstruction and no L_bidir. Adam (`train.lr`, default Adam β; Sec. 4.1).
/// An epoch is `iterations_per_epoch` iterations; the paper trains 7,000 iterations.
/// A `mesh_vae` model trains on the same windows' frames, each reconstructed on its own
/// (vae_loss), for the same iterations.
///
/// Validation (not in the paper, which has no validation set): after each epoch the
/// reconstruction term on the validation windows (sequence_data.hpp, `sequences.val_fraction`),
/// with the model in eval mode (z = μ, so nothing random and no generator advanced): Eq. 4 on
/// each clip's validation window as one free-running rollout (a window of one frame has nothing
/// to predict and is skipped), averaged over the clips; for a `mesh_vae`, vae_loss's
/// reconstruction term on all validation frames. The other terms of Eq. 3 are logged beside it
/// (`val_parts`) but not selected on: L_2 is a norm of the parameters and L_KL a regulariser, and
/// on windows of a few frames L_2 alone outweighs the reconstruction. best.pt is the epoch of
/// lowest validation loss, and `train.patience` stops training after
/// that many epochs without improvement (by more than `train.min_delta`), as in the other tasks.
/// The test windows are never used in training or selection. Without validation windows
/// (val_fraction 0, the paper's setting) best.pt and early stopping follow the training loss,
/// with a warning.
///
/// Evaluation (Table 1): only on the test windows (part `test`; not the validation windows,
/// which selected the checkpoint). Every start a of a window
/// with the last initial frame l = a + 2 inside it gives up to three predictions of frame l + h
/// for each horizon h with l + h inside the window:
///  - the network with u ∈ `initial_frames` initial frames X_{l−u+1..l} (metric `e<h>_<u>if_mm`);
///  - a `mesh_vae` model ([4], sequence_net.hpp): linear extrapolation in its latent space from
///    the two initial frames X_{l−1}, X_l (`e<h>_2if_mm`);
///  - `acap_extrapolation`, [24]'s linear extrapolation in ACAP feature space from the two
///    initial frames X_{l−1}, X_l: X_{l+h} = X_l + h (X_l − X_{l−1}) (`e<h>_2if_mm`);
///  - `hold`: the last initial frame repeated, X_{l+h} = X_l (`e<h>_1if_mm`), the floor any
///    motion model must beat;
/// and the representation's own floor, the ground-truth features decoded (`floor<h>_mm`).
/// Every method predicts the same frames. A prediction is decoded to positions (acap.hpp), each
/// connected part placed at its ground-truth centroid (ACAP features carry no translation), and
/// its error is the mean distance of its vertices to the ground truth, in mm in the character's
/// 1 m-tall frame. A character's value is the mean over its predictions; `starts<h>` counts
/// them.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "experiments/bdlstm/sequence_data.hpp"
#include "experiments/bdlstm/sequence_net.hpp"
#include "framework/core/config.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/eval/evaluator.hpp"
#include "framework/geometry/acap.hpp"
#include "framework/train/run_data.hpp"
#include "framework/train/run_options.hpp"
#include "framework/train/trainer.hpp"

namespace skinlab::bdlstm {

/// The weights of Eq. 3's terms.
struct Objective {
  double recon = 1.0, bidir = 0.5, kl = 0.1, l2 = 0.1;
};

/// The `sequences:` section of a sequence config.
struct SequenceTaskOptions {
  SequenceOptions data;
  int window = 32;
  int batch = 8;
  int iterations_per_epoch = 100;
  Objective objective;
  std::vector<int> initial_frames{1, 3};
  std::vector<int> horizons{5, 10, 15};
  std::string baseline;  ///< "", acap_extrapolation or hold
  /// Errors name the file, line and key.
  static SequenceTaskOptions from(const config::Node& node);
};

/// A validated sequence config.
struct SequenceConfig {
  train::RunOptions run;
  SequenceTaskOptions sequences;
  bool has_data = false;  ///< a `data:` section or a `sequences.folder`
  std::string model_type;  ///< bdlstm or mesh_vae; empty without a model
  /// Throws ConfigError for anything invalid, including another task, a model that is not a
  /// `bdlstm` or `mesh_vae`, both a model and a baseline, and a model run over anything but one character
  /// (the network is sized by its mesh).
  static SequenceConfig from(const config::Config& config);
};

/// A character's sequences in the network's units: the scale fitted over its frames outside the
/// test windows (training and validation frames; see the file comment).
struct ScaledCharacter {
  const SequenceCharacter* character = nullptr;
  geometry::FeatureScale scale;
  /// Every sequence's frames scaled, as float tensors #V×9.
  std::vector<std::vector<torch::Tensor>> frames;
};
ScaledCharacter scale_character(const SequenceCharacter& character);

/// The network of a config for `character` (libtorch seeded with the config's seed first).
std::shared_ptr<SequenceNet> build_network(const SequenceConfig& config,
                                           const SequenceCharacter& character);

/// The mesh VAE of a config for `character` (seeded as build_network).
std::shared_ptr<MeshVae> build_vae(const SequenceConfig& config, const SequenceCharacter& character);

/// The mesh VAE's objective on B frames (B×V×9): recon · mean ‖X̂ − X‖ (Frobenius per frame, as
/// Eq. 4) + kl · L_KL + l2 · L_2; fills `parts` (recon, kl, l2) when given.
torch::Tensor vae_loss(MeshVae& vae, const torch::Tensor& frames, const Objective& objective,
                       std::map<std::string, double>* parts = nullptr);

/// Eq. 3-5 on a rollout of `window` (L × [B×V×9]); fills `parts` (recon, bidir, kl, l2) when
/// given.
torch::Tensor sequence_loss(SequenceNet& net, const Rollout& rollout,
                            const std::vector<torch::Tensor>& window, const Objective& objective,
                            std::map<std::string, double>* parts = nullptr);

class SequenceTrainer {
 public:
  /// Validates the config, reads the dataset, builds the character's sequences, the network and
  /// Adam. Nothing is written.
  explicit SequenceTrainer(const config::Config& config);
  train::TrainResult fit(const RunDir& run, const train::FitLimits& limits = {});
  /// The bdlstm network (a mesh_vae config has none: Error).
  SequenceNet& network() {
    if (!net_) throw Error("SequenceTrainer::network: this run trains a mesh_vae");
    return *net_;
  }
  /// What is trained: the bdlstm network or the mesh VAE.
  torch::nn::Module& model() { return net_ ? static_cast<torch::nn::Module&>(*net_) : *vae_; }
  /// The training windows' (sequence, first frame) and their length.
  const std::vector<std::pair<int, int>>& windows() const { return windows_; }
  int window_length() const { return length_; }

  /// Frames [begin, end) of the character's sequence `sequence`.
  struct Span {
    int sequence = 0, begin = 0, end = 0;
  };
  /// What the validation loss is computed on: each clip's validation window (for a bdlstm, those
  /// of at least 2 frames). Empty without validation.
  const std::vector<Span>& validation_windows() const { return validation_windows_; }
  bool has_validation() const { return !validation_windows_.empty(); }
  /// The reconstruction term on the validation windows (see the file comment), deterministic,
  /// in eval mode without gradients (the model's mode is restored); adds the mean of each part
  /// of Eq. 3 to `parts` when given. NaN without validation.
  double validation_loss(std::map<std::string, double>* parts = nullptr);

 private:
  double iterate(at::Generator& rng, std::map<std::string, double>& parts);

  SequenceConfig options_;
  std::unique_ptr<SequenceData> data_;
  ScaledCharacter scaled_;
  std::vector<std::pair<int, int>> windows_;
  int length_ = 0;
  std::vector<Span> validation_windows_;
  /// Scaled frames of validation_windows_, each L × [1×V×9].
  std::vector<std::vector<torch::Tensor>> validation_;
  std::shared_ptr<SequenceNet> net_;
  std::shared_ptr<MeshVae> vae_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
  torch::Tensor initial_torch_rng_;
  bool fitted_ = false;
};

/// Evaluates a sequence run (its checkpoint, or its baseline) on the held-out windows; see the
/// file comment. Throws as eval::evaluate, and Error for a part other than `test`.
eval::EvalReport evaluate_sequence(const RunDir& run, const eval::EvalOptions& options);

/// What `skinlab generate` makes of a trained run (Sec. 3.2: generation from initial frames).
struct GenerateOptions {
  int initial_frames = 3;         ///< u: given frames X_start..X_{start+u−1}
  int frames = 15;                ///< N: frames generated after them
  std::string clip;               ///< default: the character's first clip
  int start = -1;                 ///< first initial frame; −1: the clip's held-out window start
  std::string checkpoint = "best";
  double fps = 0;                 ///< glTF playback rate; 0: the clip's, or 30 when unknown
  std::vector<std::string> overrides;  ///< applied to the run's config (e.g. data.file=...)
};

struct GeneratedSequence {
  std::string character, clip;
  int start = 0, test_begin = 0, test_end = 0, epoch = 0;
  /// Per generated frame with a ground truth in the clip: the Table 1 error (mm, 1 m frame,
  /// parts at their true centroids, as evaluate_sequence scores it).
  std::vector<double> error_mm;
};

/// Generates `frames` frames of the run's character from `initial_frames` frames of one clip
/// with the forward chain (z = μ) and writes, into the new directory `out`:
///   frame_0000.obj …  the u initial frames as given, then the N generated ones, each decoded
///                     with every connected part at its centroid in the last initial frame
///                     (ACAP features carry no translation; no ground truth is used);
///   truth_0000.obj …  the clip's own frames over the same span, as far as the clip goes;
///   sequence.glb, truth.glb  the same as glTF morph-target animations for viewing;
///   generate.json     run, checkpoint, clip, frames, held-out window and the per-frame errors.
/// Frames are in the character's normalised 1 m frame. The directory is written under a
/// temporary name and renamed at the end, so a failure leaves nothing. Throws Error when `out`
/// exists and is not empty, for a baseline run (nothing trained), a clip the character does not
/// have (listing its clips), or initial frames outside the clip (naming the range).
GeneratedSequence generate_sequence(const RunDir& run, const GenerateOptions& options,
                                    const std::filesystem::path& out);

}  // namespace skinlab::bdlstm

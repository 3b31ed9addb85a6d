#pragma once
/// \file
/// Mesh sequences for the share-weight bidirectional LSTM (Qiao et al., "Synthesizing Mesh
/// Deformation Sequences with Bidirectional LSTM"; issue 10): fixed-connectivity sequences and
/// their ACAP features (Sec. 3.1, framework/geometry/acap.hpp), with a held-out subsequence of
/// each for testing (Sec. 4.1).
///
/// Our data, honestly. Dyna and the paper's other sequences cannot be had here. Ours are real
/// game animations: every character of a prepared dataset file (e.g. the 0 A.D. characters,
/// `art/animation/**.psa`: walks, gallops, attacks, deaths of humans, horses, wolves, ...) with
/// its own clips, each clip applied to the character's artist-skinned mesh by the game's own
/// rule, linear blend skinning with pose(j) = frame(j) · bind(j)⁻¹ (both in the file, in the
/// character's normalised 1 m frame). The motion is real; the deformation is the engine's
/// skinning, so it carries LBS's artefacts and no secondary motion. Global motion is kept (ACAP
/// features are translation-invariant; a walk turns).
///
/// Template. Sec. 3.1 takes the deformation gradients with respect to "the first mesh ... the
/// template of the motion sequence". A character here has several clips, so its template is its
/// bind-pose mesh (the mesh the artist skinned), shared by all its clips; each clip is encoded
/// as a sequence starting from it (rotation vectors follow the previous frame, acap.hpp).
///
/// The representation's floor: decoding the features of the bundled 0 A.D. clips back to
/// positions is off by a median 0.4 mm (horse) to 6 mm (a low-poly human) in the 1 m frame,
/// 99th percentiles 4-19 mm (tests/bdlstm): the Poisson fit of per-vertex gradients that LBS
/// does not make integrable. Sequence errors should be read against it.
///
/// Split (Sec. 4.1: "we randomly exclude a subsequence, which takes up 20% of the dataset, as a
/// test set"): in each sequence a contiguous window of round(test_fraction · frames) frames
/// (at least 1) at a random start, drawn from the seed and the character and clip names, so it
/// does not depend on which other characters or clips the file holds.

#include <torch/torch.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/geometry/acap.hpp"
#include "framework/geometry/mesh.hpp"

namespace skinlab::bdlstm {

/// The `sequences:` section of a BiLSTM config.
///
///     sequences:
///       characters: []        # names in the dataset file; empty: every character with clips
///       frame_stride: 1       # every k-th frame (Sec. 4: every other model for slow motion)
///       min_frames: 8         # clips with fewer sampled frames are left out, with the reason
///       test_fraction: 0.2    # the held-out subsequence of each sequence (Sec. 4.1)
///       seed: 0               # draws the held-out windows
struct SequenceOptions {
  std::vector<std::string> characters;
  int frame_stride = 1;
  int min_frames = 8;
  double test_fraction = 0.2;
  std::uint64_t seed = 0;
  /// Decodes and checks the section (every field optional); errors name the file, line, key.
  /// `other_keys` are accepted and left to the caller (the task's own keys, sequence_task.hpp).
  static SequenceOptions from(const config::Node& node, std::vector<std::string> other_keys = {});
};

/// One clip on one mesh.
struct MeshSequence {
  std::string clip;
  double fps = 0;                          ///< of the sampled frames (clip fps / stride; 0: unknown)
  std::vector<Eigen::MatrixXd> positions;  ///< #V×3 per frame, normalised frame (metres, 1 m tall)
  std::vector<Eigen::MatrixXd> features;   ///< #V×9 ACAP features per frame w.r.t. the template
  int test_begin = 0, test_end = 0;        ///< held-out frames [test_begin, test_end)
  int num_frames() const { return static_cast<int>(positions.size()); }
};

struct SequenceCharacter {
  std::string name;
  int dataset_index = 0;
  geometry::Mesh rest;  ///< the template: the bind-pose mesh
  std::shared_ptr<const geometry::AcapEncoder> acap;
  torch::Tensor one_ring;  ///< #E×2 int64 mesh edges (the mesh convolution's N(i))
  std::vector<MeshSequence> sequences;
  int num_vertices() const { return rest.num_vertices(); }
};

class SequenceData {
 public:
  /// Builds the sequences of every selected character of `dataset` (read from `file`, named in
  /// messages). A character without clips, and a clip with fewer than `min_frames` sampled
  /// frames, is left out with the reason (`excluded()`). Throws IoError naming the file for a
  /// character name it does not hold, a clip whose joint count is not the character's (naming
  /// both), or when nothing is left.
  SequenceData(const data::Dataset& dataset, const std::string& file,
               const SequenceOptions& options);

  const SequenceOptions& options() const { return options_; }
  const std::vector<SequenceCharacter>& characters() const { return characters_; }
  /// "character: reason" or "character/clip: reason" for each thing left out.
  const std::vector<std::string>& excluded() const { return excluded_; }

 private:
  SequenceOptions options_;
  std::vector<SequenceCharacter> characters_;
  std::vector<std::string> excluded_;
};

/// The held-out window [begin, end) of a sequence of `frames` frames: round(fraction · frames)
/// frames (at least 1, at most frames − 1 so something is left to train on; none for a
/// 1-frame sequence) at a start drawn from `seed` and `key` (FNV-1a of the key, then a
/// splitmix64 step).
std::pair<int, int> held_out_window(int frames, double fraction, std::uint64_t seed,
                                    const std::string& key);

}  // namespace skinlab::bdlstm

#pragma once
/// \file
/// Mesh sequences for the share-weight bidirectional LSTM (Qiao et al., "Synthesizing Mesh
/// Deformation Sequences with Bidirectional LSTM"): fixed-connectivity sequences and
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
/// test set"): in each sequence a contiguous test window of round(test_fraction · frames)
/// frames (at least 1) at a random start, drawn from the seed and the character and clip names,
/// so it does not depend on which other characters or clips the file holds. The paper has no
/// validation set; ours (not in the paper, for choosing best.pt and early stopping) is a second
/// contiguous window of round(val_fraction · frames) frames (at least 1) right next to the test
/// window: immediately before it where it fits, else immediately after it. The test window is
/// drawn as without validation, so it does not move with val_fraction and test numbers stay
/// comparable; val_fraction 0 is the paper's split. The training frames are the rest: at most
/// two stretches, before and after the two held-out windows. A sequence without room for both
/// windows and a training frame is left out with the reason, as a short one is.

#include <torch/torch.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
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
///       val_fraction: 0       # a validation window beside it (best.pt, early stopping); 0: none,
///                             # the paper's split (val_fraction + test_fraction < 1). 0 by
///                             # default, so a run saved before the key existed resumes with
///                             # its own split; configs/bdlstm/task.yaml sets 0.1
///       seed: 0               # draws the held-out windows
///       folder: ""            # a folder of OBJ sequences instead of the dataset file (below)
///       up: [0, 1, 0]         # a folder's up axis (its meshes are turned to Y up)
struct SequenceOptions {
  std::vector<std::string> characters;
  std::string folder;
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  int frame_stride = 1;
  int min_frames = 8;
  double test_fraction = 0.2;
  double val_fraction = 0;
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
  int test_begin = 0, test_end = 0;        ///< held-out test frames [test_begin, test_end)
  /// Validation frames [val_begin, val_end), adjacent to the test window (before it where it
  /// fits); empty (0, 0) when val_fraction is 0.
  int val_begin = 0, val_end = 0;
  int num_frames() const { return static_cast<int>(positions.size()); }
  /// The frames held out from training, test and validation together: one contiguous span.
  std::pair<int, int> held_out() const {
    if (val_begin == val_end) return {test_begin, test_end};
    return {std::min(test_begin, val_begin), std::max(test_end, val_end)};
  }
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
  /// A user's own sequences (e.g. Dyna's registrations), read from `options.folder`:
  ///
  ///     <folder>/<character>/template.obj      # optional: the template (Sec. 3.1)
  ///     <folder>/<character>/<clip>/*.obj      # one clip, its frames in natural name order
  ///                                            # (frame2.obj before frame10.obj)
  ///
  /// Every frame of a character must have its template's vertices (in the same order) and
  /// faces; without template.obj the template is the first frame of the first clip (the
  /// paper's "first mesh"). Each character is rotated so that `options.up` becomes +Y, then
  /// scaled and moved by the similarity that makes its template 1 m tall with its lowest point
  /// at y = 0 (geometry/normalize.hpp), so errors are in the same 1 m frame as the game
  /// characters'. Characters and clips are sub-directories in sorted order (`characters`
  /// selects among them); fps is unknown (0). Throws IoError naming the folder, the file and
  /// the vertex or face for a missing folder, an unreadable OBJ, or a frame whose vertex count
  /// or faces differ from its template's; and as the other constructor when nothing is left.
  explicit SequenceData(const SequenceOptions& options);

  /// Builds the sequences of every selected character of `dataset` (read from `file`, named in
  /// messages). A character without clips, a clip with fewer than `min_frames` sampled frames,
  /// and a clip without room for its test and validation windows and a training frame
  /// (validation_window), is left out with the reason (`excluded()`). Throws IoError naming the
  /// file for a character name it does not hold, a clip whose joint count is not the
  /// character's (naming both), or when nothing is left.
  SequenceData(const data::Dataset& dataset, const std::string& file,
               const SequenceOptions& options);

  const SequenceOptions& options() const { return options_; }
  /// Where the sequences came from (the dataset file or the folder), for messages.
  const std::string& source() const { return source_; }
  const std::vector<SequenceCharacter>& characters() const { return characters_; }
  /// "character: reason" or "character/clip: reason" for each thing left out.
  const std::vector<std::string>& excluded() const { return excluded_; }

 private:
  /// Draws the held-out windows of `sequence`, encodes its positions and adds it to `out`, or
  /// records it as excluded when it has fewer than min_frames frames or no room for the windows.
  void add_sequence(SequenceCharacter& out, MeshSequence sequence);
  /// Keeps `out` if it has a sequence (else records why not); throws when nothing is left.
  void add_character(SequenceCharacter out, const std::string& why_empty);
  void finish();

  SequenceOptions options_;
  std::string source_;
  std::vector<SequenceCharacter> characters_;
  std::vector<std::string> excluded_;
};

/// The held-out window [begin, end) of a sequence of `frames` frames: round(fraction · frames)
/// frames (at least 1, at most frames − 1 so something is left to train on; none for a
/// 1-frame sequence) at a start drawn from `seed` and `key` (FNV-1a of the key, then a
/// splitmix64 step).
std::pair<int, int> held_out_window(int frames, double fraction, std::uint64_t seed,
                                    const std::string& key);

/// The validation window [begin, end) of a sequence of `frames` frames whose test window is
/// `test` (held_out_window): round(fraction · frames) frames, at least 1, immediately before
/// the test window when it fits there, else immediately after it. Empty, (0, 0), for fraction 0;
/// nullopt when the window fits on neither side or the two windows leave no training frame.
std::optional<std::pair<int, int>> validation_window(int frames, std::pair<int, int> test,
                                                     double fraction);

}  // namespace skinlab::bdlstm

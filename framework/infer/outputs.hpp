#pragma once
/// \file
/// What `skinlab predict` and `skinlab-predict` write and what `skinlab score` reads, as
/// library code both programs call (torch-free): a prediction written in the input's own frame, vertex order and joint names
///
///     .glb / .gltf   glTF 2.0 skin (geometry/gltf_export.hpp): joints, inverse bind matrices,
///                    JOINTS_0/WEIGHTS_0 with each vertex's 4 largest weights renormalised
///     _rig.txt       RigNet rig text (geometry/rig_io.hpp): every kept weight
///     .h5            /weights (#V×#B float32, bones in RigNet's order), /joint_weights (#V×#J),
///                    /bones (#B×2 start, end joints), /joint_names, /vertices (#V×3, input
///                    frame); attributes model, distance, prune, character
///
/// and another method's weights put onto a character's own joints, to be scored against its
/// artist weights. Every file is written whole (atomic rename).

#include <filesystem>
#include <string>

#include "framework/geometry/load_character.hpp"
#include "framework/infer/prediction.hpp"

namespace skinlab::infer {

enum class OutputKind { gltf, rig, h5 };

/// The kind of `out` by its extension; Error naming the file for any other.
OutputKind output_kind(const std::filesystem::path& out);

/// Writes prediction `p` of `input` to `out` (kind by extension). `model` (the model's
/// description), `distance` and `prune` are recorded in .h5.
void write_prediction(const std::filesystem::path& out, const geometry::Character& input,
                      const Prediction& p, const std::string& model, const std::string& distance,
                      double prune);

/// Another method's weights on the joints of `truth`.
struct OtherWeights {
  geometry::SparseWeights weights;  ///< #V×#J of truth, rows normalised (unweighted rows zero)
  int unweighted = 0;               ///< vertices the other method left without weight
};

/// Reads `file` (RigNet rig text, or any file load_character reads with the same vertex count
/// as `truth`) and maps its joints by name onto `truth`'s skeleton. Error naming the file for a
/// different vertex count, a joint `truth` does not have, or — unless `allow_unweighted` — a
/// vertex without weight. `truth_name` names `truth` in messages.
OtherWeights read_other_weights(const std::filesystem::path& file, const geometry::Character& truth,
                                const std::string& truth_name, bool allow_unweighted);

}  // namespace skinlab::infer

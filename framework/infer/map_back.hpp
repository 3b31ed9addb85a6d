#pragma once
/// \file
/// From the network's output back to the character a user gave, without libtorch, shared by
/// `skinlab predict`, `skinlab eval` and the Eigen-only `skinlab-predict`:
///
/// - the 0.25 weight pruning every compared method gets (HeterSkinNet Sec. 4.5);
/// - rows of the prepared (merged, subdivided) vertices at the source vertices
///   (PreparedCharacter::vertex_map, Sec. 4.1's merge of co-located vertices undone);
/// - bone weights as per-joint weights (a bone moves with its start joint: the inverse of the
///   bone-level rule of data/preprocess.hpp);
/// - the skeleton in the source file's frame with names a rig text can hold.

#include <string>
#include <vector>

#include "framework/data/dataset_file.hpp"
#include "framework/geometry/skeleton.hpp"
#include "framework/geometry/skin_weights.hpp"

namespace skinlab::infer {

/// Weight pruning of the compared methods (HeterSkinNet Sec. 4.5, "0.25 weight pruning
/// threshold"; RigNet's run_skinning.py and Puppeteer's skinning/main.py do the same): in every
/// row of W (#V×#B), weights below `fraction` × the row's maximum are set to 0 and the row is
/// divided by its new sum (an all-zero row stays zero). `fraction` = 0 leaves W unchanged.
/// Pruning is idempotent (kept weights stay above the threshold after renormalisation), so a
/// prediction that a model has already pruned is not changed by a metric pruning it again.
/// Error unless 0 ≤ fraction ≤ 1.
void prune_rows(data::RowMatrixXd& W, double fraction);

/// Rows of `W` (#V×C, prepared vertices) at the source vertices: row i of the result is row
/// vertex_map[i]. Throws Error for a map entry outside [0, #V).
data::RowMatrixXf to_source_vertices(const data::RowMatrixXf& W, const std::vector<int>& vertex_map);

/// #V×#J joint weights from #V×#B bone weights: a bone's weight belongs to its start joint
/// (RigNet; the inverse of the bone-level rule of data/preprocess.hpp). Exact zeros are not
/// stored; each value is the float32 sum rounded to its shortest decimal form.
geometry::SparseWeights joint_weights_of(const data::RowMatrixXf& W, const data::RowMatrixXi& bones,
                                         int num_joints);

/// Joint names made writable in a rig file: whitespace and '#' become '_', an empty name becomes
/// "joint", and a name that then collides gets a suffix `_2`, `_3`, ...
std::vector<std::string> rig_joint_names(const std::vector<std::string>& names);

/// The character's skeleton in its source file's frame (joint positions mapped through the
/// inverse of PreparedCharacter::normalisation), with rig_joint_names.
geometry::Skeleton source_skeleton(const data::PreparedCharacter& character);

}  // namespace skinlab::infer

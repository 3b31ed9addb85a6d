#pragma once
/// \file
/// RigNet's rig text format (Xu et al. 2020, the `*_rig.txt` files of ModelsResource-RigNetv1):
///
///     joints NAME x y z          one per joint, in index order
///     root NAME                  exactly one
///     hier PARENT CHILD          one per non-root joint
///     skin VID J1 w1 J2 w2 ...   one per vertex (0-based VID), weights by joint name
///
/// Weights are per joint: a bone's weight belongs to its start joint.

#include <filesystem>
#include <string>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

/// What read_rig does with `skin` lines that do not fit the mesh.
enum class SkinLines {
  /// Every problem is an error (the list at read_rig): scoring and comparing with the file's
  /// weights need them whole.
  require,
  /// Prediction does not use the input's weights, and rig texts often carry the weights of
  /// another mesh: RigNet's quick-start pairs each remeshed `<id>_remesh.obj` with
  /// `<id>_ori_rig.txt`, whose `skin` lines belong to the original mesh. The first problem of
  /// the `skin` lines (the error `require` would throw, "file:line: vertex 1040 is out of range"
  /// or "file: vertex 866 has no weight") is logged once as a warning and kept in
  /// Rig::ignored_skin, and the rig comes back without weights. `joints`, `root` and `hier`
  /// lines stay strict: a broken skeleton is still an error naming the line.
  ignore_mismatch,
};

struct Rig {
  Skeleton skeleton;
  SparseWeights weights;  ///< #V×#J; 0×0 when the file has no `skin` lines
  /// With SkinLines::ignore_mismatch: why the `skin` lines were dropped (the message `require`
  /// would have thrown); empty when they fit or under `require`.
  std::string ignored_skin;
};

/// Reads a rig file for a mesh of `num_vertices` vertices. Every malformed line is a
/// GeometryError "file:line: message": unknown keyword, wrong field count, bad number,
/// duplicate joint, a `root`/`hier`/`skin` naming an unknown joint, a joint with two parents, a
/// `root` that is not the hierarchy's root, a vertex id out of range or given twice, an odd
/// joint/weight list. Then the skeleton is validated (cycles, several roots) and, when `skin`
/// lines exist, the weights with `check_weights` (every vertex weighted, rows sum to 1). `skin`
/// decides whether a problem of the `skin` lines is an error or a warning (SkinLines).
Rig read_rig(const std::filesystem::path& file, int num_vertices, const WeightCheck& check = {},
             SkinLines skin = SkinLines::require);

/// Writes a rig file atomically, numbers in shortest round-trip form (reading it back gives
/// bit-identical positions and weights). Weights may be empty (then no `skin` lines).
void write_rig(const std::filesystem::path& file, const Skeleton& skeleton,
               const SparseWeights& weights);

/// An OBJ mesh with its RigNet rig file, validated as a Character named after the OBJ file.
Character read_obj_rig(const std::filesystem::path& obj, const std::filesystem::path& rig,
                       const WeightCheck& check = {}, SkinLines skin = SkinLines::require);

}  // namespace skinlab::geometry

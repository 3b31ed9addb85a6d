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

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

struct Rig {
  Skeleton skeleton;
  SparseWeights weights;  ///< #V×#J; 0×0 when the file has no `skin` lines
};

/// Reads a rig file for a mesh of `num_vertices` vertices. Every malformed line is a
/// GeometryError "file:line: message": unknown keyword, wrong field count, bad number,
/// duplicate joint, a `root`/`hier`/`skin` naming an unknown joint, a joint with two parents, a
/// `root` that is not the hierarchy's root, a vertex id out of range or given twice, an odd
/// joint/weight list. Then the skeleton is validated (cycles, several roots) and, when `skin`
/// lines exist, the weights with `check_weights` (every vertex weighted, rows sum to 1).
Rig read_rig(const std::filesystem::path& file, int num_vertices, const WeightCheck& check = {});

/// Writes a rig file atomically, numbers in shortest round-trip form (reading it back gives
/// bit-identical positions and weights). Weights may be empty (then no `skin` lines).
void write_rig(const std::filesystem::path& file, const Skeleton& skeleton,
               const SparseWeights& weights);

/// An OBJ mesh with its RigNet rig file, validated as a Character named after the OBJ file.
Character read_obj_rig(const std::filesystem::path& obj, const std::filesystem::path& rig,
                       const WeightCheck& check = {});

}  // namespace skinlab::geometry

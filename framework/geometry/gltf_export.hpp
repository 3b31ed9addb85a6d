#pragma once
/// \file
/// A skinned character as a glTF 2.0 asset (Khronos glTF 2.0 specification, Sec. 3.7.3
/// "Skins"), written with TinyGLTF: `.glb` (binary container) or `.gltf` (JSON with the buffer
/// embedded as a base64 data URI). What `skinlab predict` hands to Blender, game engines and any
/// other glTF importer.
///
/// Layout of the asset:
///   - one node per joint, in skeleton order (node j is joint j), in its bind pose: joint j's
///     global transform G_j = [R_j | p_j] puts it at its position p_j, and R_j turns the local +Y
///     axis towards the centroid of its children (the shortest such rotation; a leaf, or a joint
///     whose children all sit on it, keeps its parent's R; the root's parent R is the identity).
///     glTF stores joints, not bones; importers draw and bind a joint's bone along its local +Y
///     (Blender 3.4's default "Blender" bone heuristic does), so without R every bone would
///     point up and Blender's automatic weights would follow those wrong bones. Nodes carry the
///     local translation and rotation G_parent⁻¹ G_j, no scale;
///   - one skin over those nodes, `skeleton` = the root joint, inverse bind matrices
///     IBM_j = G_j⁻¹ (Sec. 3.7.3.1), so the bind pose leaves every vertex where it is;
///   - one mesh node carrying the mesh and the skin (its own transform is the identity, as the
///     specification asks of skinned mesh nodes); the scene's roots are the root joint and the
///     mesh node;
///   - one triangle primitive: POSITION (float32 VEC3 with min/max), unsigned 32-bit indices,
///     NORMAL when given, and the weights as JOINTS_n (unsigned 8-bit, or 16-bit above 256
///     joints) and WEIGHTS_n (float32) sets of four influences each.
///
/// Weights. Per vertex the non-zero per-joint weights are sorted by decreasing value (ties: lower
/// joint first) and the largest `max_influences` are kept and renormalised to sum to 1; they are
/// packed four to a set, so a vertex with at most four influences needs JOINTS_0/WEIGHTS_0 only
/// and a second set is written only when some vertex keeps more than four (unused slots are
/// joint 0 with weight 0, as the specification requires).

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

struct GltfExportOptions {
  /// Influences kept per vertex, 1..8; 4 is what every glTF importer reads (one set).
  int max_influences = 4;
  /// #V×3 vertex normals to store, or empty for none.
  Eigen::MatrixX3d normals;
};

/// Writes `character` (mesh, skeleton and per-joint weights #V×#J, which must be present) to
/// `file`, `.glb` or `.gltf` by its extension, atomically. Throws Error for another extension, a
/// bad option and a character without weights, and IoError when the file cannot be written.
void write_gltf(const std::filesystem::path& file, const Character& character,
                const GltfExportOptions& options = {});

/// A mesh animation as a glTF 2.0 asset of morph targets (Sec. 3.7.2.2 "Morph Targets",
/// Sec. 3.11 "Animations"), which Blender imports as shape keys and a viewer plays: the mesh
/// (faces F, #F×3) in frames[0], one morph target per later frame t holding frames[t] − frames[0],
/// and one animation of the node's morph weights in which keyframe t (time t / fps) sets target
/// t − 1 to 1 and the others to 0, linearly interpolated in between, so playback morphs from
/// frame to frame. Written atomically; `.glb` or `.gltf` by extension. Throws Error for another
/// extension, no frame, fps ≤ 0, a frame whose size differs from frame 0's (naming it), a
/// non-finite coordinate or a face index out of range; IoError when the file cannot be written.
void write_gltf_morph_animation(const std::filesystem::path& file, const std::string& name,
                                const Eigen::MatrixXi& F, const std::vector<Eigen::MatrixXd>& frames,
                                double fps);

}  // namespace skinlab::geometry

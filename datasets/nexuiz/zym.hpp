#pragma once
/// \file
/// Reader of ZYMOTIC models, type 1 (`.zym`; Forest "LordHavoc" Hale's skeletal format for
/// DarkPlaces, used by Nexuiz for its player characters). No separate specification exists; the
/// layout is that of DarkPlaces' `model_zymotic.h` and its loader `Mod_ZYMOTICMODEL_Load`
/// (model_alias.c), and of the exporter `zmodel.c` (DarkPlaces tools).
///
/// Layout (all big-endian): a 140-byte header — "ZYMOTICMODEL" (12 bytes), type (1), file size,
/// bounds (mins[3], maxs[3], radius), #vertices, #triangles, #shaders, #bones, #scenes — then nine
/// lumps {start, length}: scenes (76 B: name[32], mins[3], maxs[3], radius, framerate, flags,
/// first pose, #poses), poses (float[#poses][#bones][3][4]: row-major 3×4 [R|t] of each bone
/// relative to its parent), bones (40 B: name[32], flags, parent < own index), per-vertex bone
/// counts (int32), vertex influences (16 B: bone, origin[3] in that bone's space), texture
/// coordinates, the render list (per shader: #triangles, then 3 int32 vertex indices each),
/// shader names (32 B each) and triangle zones.
///
/// The bind pose is pose 0, as in DarkPlaces, which rebuilds the base mesh by transforming each
/// vertex's bone-space origin with pose 0's global bone transform: the exporter's reference
/// ("mesh") pose is not stored. Skinning is rigid: every exporter writes one bone per vertex
/// ("always 1 in smd") and DarkPlaces rejects any other count, because the format has no weight
/// per influence; so does this reader. The exporter bakes the model scale into the root bones'
/// matrices (Nexuiz players: 0.7); vertices are placed with the scaled matrices, and the stored
/// transforms are their rigid parts (the uniform scale cancels in every skinning transform).
/// Helper bones that neither skin a vertex nor are an ancestor of one (weapon attachment points,
/// exporter roots) may have all-zero matrices; they are flagged `RiggedModel::unusable`.
/// Triangles are stored clockwise (Quake); like DarkPlaces we reverse them to counter-clockwise.
/// Frame and units as in the file (Quake units, Z up).

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "datasets/rigged_model.hpp"

namespace skinlab::datasets::nexuiz {

struct ZymScene {
  std::string name;
  double fps = 0;    ///< frames per second as stored
  bool loop = true;  ///< false when ZYMSCENEFLAG_NOLOOP is set
  int first_pose = 0;
  int num_poses = 0;
};

struct ZymFile {
  /// V #V×3 (pose 0), F #F×3, bones with names, parents and global pose-0 transforms as `bind`,
  /// W #V×#B with a single 1 per row. Name left empty.
  RiggedModel model;
  std::vector<std::string> shader_names;
  std::vector<ZymScene> scenes;
  std::vector<Transforms> poses;  ///< poses[p][b]: global rigid transform of bone b in pose p
};

/// Parses `bytes`. Throws IoError "<source>: <element> (byte offset N): <problem>" for a wrong
/// magic or type, a truncated file or lump, and out-of-range bone, vertex, pose or scene indices
/// (naming the element), a vertex with other than one bone, or a bone matrix that is not a
/// rotation times the model's one uniform scale.
ZymFile read_zym(std::string_view bytes, const std::string& source);
ZymFile read_zym_file(const std::filesystem::path& file);

}  // namespace skinlab::datasets::nexuiz

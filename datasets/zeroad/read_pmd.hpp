#pragma once
/// \file
/// 0 A.D.'s binary mesh format PMD ("PSMD"), as the engine reads it (CModelDef::Load in
/// source/graphics/ModelDef.cpp) and its COLLADA converter writes it (WritePMD in
/// source/collada/PMDConvert.cpp). Little-endian, after the 12-byte header (ByteReader):
///
///     u32 #V; [version >= 4] u32 #UV sets
///     #V × { f32 position[3]; f32 normal[3]; #UV × f32 uv[2]; u8 bone[4]; f32 weight[4] }
///     u32 #F; #F × u16 vertex[3]
///     u32 #B; #B × { f32 translation[3]; f32 rotation quaternion (x, y, z, w) }
///     [version >= 2] u32 #P; #P × { u32 length, name; f32 position[3]; f32 rotation[4];
///                                    u8 bone (0xFF: none) }
///
/// Unused influence slots have bone 0xFF. Bones are the bind pose as global (object-space)
/// transforms, rotation then translation, in the order of the target `standard_skeleton`
/// (read_skeletons.hpp). Versions 1–4 are read, as the engine does; versions ≤ 2 store vertices
/// relative to the bind pose, which we skin into object space as the engine does. Positions are
/// in the game's frame (Y up, left-handed, metres-like "game units"). Debian's 0ad-data 0.0.26
/// ships version 4 only.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace skinlab::datasets::zeroad {

struct PmdPropPoint {
  std::string name;
  Eigen::Vector3d position;  ///< relative to the bone (or the object when bone < 0)
  Eigen::Quaterniond rotation;
  int bone = -1;  ///< bone index, -1 for none
};

struct Pmd {
  int version = 0;
  Eigen::MatrixXd positions;            ///< #V×3 object-space positions
  Eigen::MatrixXd normals;              ///< #V×3
  Eigen::MatrixXd uvs;                  ///< #V×(2·#UV sets)
  Eigen::MatrixXi bone_indices;         ///< #V×4, -1 for an unused slot
  Eigen::MatrixXd bone_weights;         ///< #V×4, 0 for an unused slot
  Eigen::MatrixXi faces;                ///< #F×3 vertex indices
  std::vector<Eigen::Isometry3d> bind;  ///< #B bind-pose global bone transforms
  std::vector<PmdPropPoint> props;

  int num_bones() const { return static_cast<int>(bind.size()); }
};

/// Parses PMD `bytes`. Throws Error "source: byte offset N: ..." naming the element (vertex,
/// face, bone, prop point) for: a wrong magic, an unsupported version, truncation, non-finite
/// numbers, a face index ≥ #V, a bone index ≥ #B (the engine's bind-shape special case, index
/// = #B, included), trailing bytes and a header size that disagrees with the file.
Pmd read_pmd(const std::string& bytes, const std::string& source);

}  // namespace skinlab::datasets::zeroad

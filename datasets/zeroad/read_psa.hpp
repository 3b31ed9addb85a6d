#pragma once
/// \file
/// 0 A.D.'s binary animation format PSA ("PSSA"), as the engine reads it
/// (CSkeletonAnimDef::Load in source/graphics/SkeletonAnimDef.cpp). Little-endian, after the
/// 12-byte header (ByteReader):
///
///     u32 length, name; f32 frame time (milliseconds); u32 #B keys per frame; u32 #F frames
///     #F × #B × { f32 translation[3]; f32 rotation quaternion (x, y, z, w) }
///
/// Keys are frame-major. Each key is the bone's global (object-space) transform at that frame,
/// rotation then translation, in the bone order of the mesh's standard skeleton, so the engine
/// skins a vertex by key(j) · bind(j)⁻¹ with bind(j) from the PMD. Version 1 is the only one
/// the engine writes and reads (Debian's 0ad-data 0.0.26 ships version 1 only).

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace skinlab::datasets::zeroad {

struct Psa {
  std::string name;          ///< usually empty
  double frame_time_ms = 0;  ///< milliseconds per frame
  int num_bones = 0;         ///< #B keys per frame
  /// frames[f][b]: bone b's global transform at frame f
  std::vector<std::vector<Eigen::Isometry3d>> frames;
};

/// Parses PSA `bytes`. Throws Error "source: byte offset N: ..." naming the frame and bone for:
/// a wrong magic, an unsupported version, truncation, non-finite or zero quaternions, a
/// non-positive frame time, trailing bytes and a header size that disagrees with the file.
Psa read_psa(const std::string& bytes, const std::string& source);

}  // namespace skinlab::datasets::zeroad

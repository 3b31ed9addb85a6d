#pragma once
/// \file
/// Reader of Inter-Quake Model files, version 2 (Lee Salzman, 2010–2011; the public
/// specification is `iqm.txt` with `iqm.h` in github.com/lsalzman/iqm). Cube 2/Sauerbraten stores
/// its player models in it (cube2-data), with every animation clip in a separate mesh-less file.
///
/// Layout (all little-endian): a 124-byte header (magic "INTERQUAKEMODEL\0", version, file size,
/// flags, then count/offset pairs) locates a string table, meshes (24 B: name, material, first
/// vertex, #vertices, first triangle, #triangles), vertex arrays (20 B: type, flags, format,
/// components, offset; one array per attribute, not interleaved), triangles (3×uint32), joints
/// (48 B: name, parent, translate[3], rotate quaternion xyzw[4], scale[3]), poses (88 B: parent,
/// channel mask, 10 channel offsets and scales), frames (uint16 channel values) and animations
/// (20 B: name, first frame, #frames, frame rate, flags).
///
/// Transforms: a joint's and a pose's local transform maps its own space to its parent's,
/// `output = (input·scale)·rotation + translation`, i.e. L = Translate · Rotate · Scale; global
/// transforms compose down the hierarchy, G_j = G_parent · L_j. Vertex positions are in the model
/// frame of the bind ("base") pose, so G_j(bind) is the bind transform of LBS. A frame's channel c
/// of pose j is `channeloffset[c] + (mask bit c ? value · channelscale[c] : 0)`, values consumed
/// in pose-then-channel order (channels 0–2 translation, 3–6 quaternion xyzw, 7–9 scale).
///
/// Supported: position as float×3, blend indexes and weights as ubyte×4 (what the exporter
/// writes and every engine reads; weights are renormalised from their uint8 sum, nominally 255).
/// Scaled joints are rejected (our transforms are rigid); cube2-data has none.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "datasets/rigged_model.hpp"

namespace skinlab::datasets::cube2 {

/// One animation: its frames' parent-relative pose transforms.
struct IqmClip {
  std::string name;
  double fps = 0;                 ///< frames per second as stored (0 when unknown)
  bool loop = false;              ///< IQM_LOOP flag
  std::vector<Transforms> local;  ///< local[f][p]: pose p at frame f, relative to its parent
};

/// Everything a file holds. A model file has geometry and joints; an animation file (as cube2
/// stores its clips) has poses and clips only.
struct IqmFile {
  std::vector<std::string> mesh_names;
  /// Geometry and skeleton: V #V×3, F #F×3, joints with names, parents, global bind transforms,
  /// weights W #V×#J (empty 0×0 when the file has no blend arrays). Name left empty.
  RiggedModel model;
  bool has_blend_weights = false;
  std::vector<int> pose_parents;  ///< #poses parent indices (-1 for a root)
  std::vector<IqmClip> clips;

  bool has_geometry() const { return model.V.rows() > 0; }
};

/// Parses `bytes`. Throws IoError "<source>: <element> (byte offset N): <problem>" for a wrong
/// magic or version, a truncated file, an offset or index out of range (naming the mesh, vertex,
/// triangle, joint, pose or animation), an unsupported vertex-array format or a scaled joint.
/// Without `read_clips` poses, frames and animations are not read (pose_parents and clips stay
/// empty), so a model whose clips scale joints (raylib's guy.iqm) still gives its bind pose.
IqmFile read_iqm(std::string_view bytes, const std::string& source, bool read_clips = true);
/// Reads and parses a file; errors name the file path.
IqmFile read_iqm_file(const std::filesystem::path& file, bool read_clips = true);

/// Global transforms of every pose of every frame of `clip`, composed with `parents`.
std::vector<Transforms> global_frames(const IqmClip& clip, const std::vector<int>& parents,
                                      const std::vector<std::string>& names,
                                      const std::string& source);

}  // namespace skinlab::datasets::cube2

#pragma once
/// \file
/// One entry point for "a character file a user has": an OBJ mesh with a RigNet rig text file,
/// or any file the Open Asset Importer reads with a skeleton (FBX, glTF/GLB, DAE, B3D, ...).

#include <filesystem>
#include <vector>

#include "framework/geometry/rig_io.hpp"
#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

/// With `rig` given, `file` must be an OBJ mesh and `rig` its RigNet rig file (read_obj_rig,
/// with `skin` deciding what a `skin` line that does not fit the mesh is); an OBJ without `rig`
/// takes the rig text next to it (rig_beside). Any other `file` is imported through assimp
/// (import_character; identical vertices are joined, except in glTF/GLB files, whose indexed
/// vertex list is kept as it is so results map onto the file's own vertices). The result is
/// validated, in the file's frame and units. Errors name the file.
Character load_character(const std::filesystem::path& file, const std::filesystem::path& rig = {},
                         SkinLines skin = SkinLines::require);

/// The rig text files an OBJ `<dir>/<stem>.obj` may have next to it, in the order they are
/// tried: `<stem>_rig.txt` (what `skinlab predict` and ModelsResource-RigNetv1 write),
/// `<stem>.txt`, and for RigNet's quick-start meshes `<id>_remesh.obj` also `<id>_ori_rig.txt`
/// (the rig of the original mesh; its `skin` lines belong to that mesh, see SkinLines). None
/// for a file of another format: those carry their own skeleton.
std::vector<std::filesystem::path> rig_candidates(const std::filesystem::path& obj);

/// The first of rig_candidates(obj) that exists; empty when none does (or `obj` is no OBJ).
std::filesystem::path rig_beside(const std::filesystem::path& obj);

/// Whether `file`'s extension is one of a character file (case-insensitive): obj, fbx, glb,
/// gltf, dae, b3d, iqm, smd, x, md5mesh. A directory given to `skinlab predict` contributes
/// these files; others (rig texts, textures, .blend) are not characters of their own.
bool is_character_file(const std::filesystem::path& file);

}  // namespace skinlab::geometry

#pragma once
/// \file
/// One entry point for "a character file a user has": an OBJ mesh with a RigNet rig text file,
/// or any file the Open Asset Importer reads with a skeleton (FBX, glTF/GLB, DAE, B3D, ...).

#include <filesystem>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

/// With `rig` given, `file` must be an OBJ mesh and `rig` its RigNet rig file (read_obj_rig);
/// otherwise `file` is imported through assimp (import_character; identical vertices are joined,
/// except in glTF/GLB files, whose indexed vertex list is kept as it is so results map onto the
/// file's own vertices). The result is validated, in the file's frame and units. Errors name
/// the file.
Character load_character(const std::filesystem::path& file, const std::filesystem::path& rig = {});

}  // namespace skinlab::geometry

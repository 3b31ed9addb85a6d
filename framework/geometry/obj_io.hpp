#pragma once
/// \file
/// Wavefront OBJ meshes, positions and triangles only. Our own reader rather than assimp's:
/// RigNet's rig files address vertices by their OBJ `v` line order, and assimp's OBJ importer
/// splits vertices by normal/UV and reorders them, which would break that correspondence.

#include <filesystem>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

/// Reads `v` and `f` lines (`f` entries may be `i`, `i/t`, `i//n`, `i/t/n`, negative = relative);
/// polygons are split into a fan of triangles; other statements are ignored. Vertices keep file
/// order. Throws GeometryError "file:line: ..." for malformed lines and indices out of range,
/// IoError if the file cannot be read. The result is validated.
Mesh read_obj(const std::filesystem::path& file);

/// Writes `v` and `f` lines with round-trip precision, atomically.
void write_obj(const std::filesystem::path& file, const Mesh& mesh);

}  // namespace skinlab::geometry

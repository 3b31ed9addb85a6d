#pragma once
/// \file
/// The connected parts of a mesh: vertices joined by the faces that share them (union-find over
/// shared vertex indices). Co-located but unshared vertices are different parts; merge them first
/// (merge_vertices.hpp) where position should join them.

#include <vector>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

/// The part of every vertex, joined by every face: entry v is the representative vertex of v's
/// part, the same for all its vertices, and the one vertex r of the part with entry r == r; a
/// vertex in no face is its own part. O(#F α(#V)).
std::vector<int> vertex_parts(const Mesh& mesh);

/// As above, joined by the faces listed in `faces` only (rows of Mesh::F), for methods that
/// leave some faces out (degenerate ones).
std::vector<int> vertex_parts(const Mesh& mesh, const std::vector<int>& faces);

}  // namespace skinlab::geometry

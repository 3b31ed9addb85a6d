#pragma once
/// \file
/// Triangle mesh: the geometry every distance, graph and loss works on.

#include <Eigen/Core>
#include <string>

#include "framework/core/error.hpp"

namespace skinlab::geometry {

/// Invalid geometry, skeleton or weights. The message names the source and the element.
class GeometryError : public Error {
 public:
  using Error::Error;
};

struct Mesh {
  Eigen::MatrixXd V;  ///< #V×3 vertex positions (metres after normalisation)
  Eigen::MatrixXi F;  ///< #F×3 triangle vertex indices into V

  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_faces() const { return static_cast<int>(F.rows()); }

  /// Throws GeometryError, prefixed by `source` (a file name or character name), for: no
  /// vertices or no faces, a V or F of the wrong width, non-finite coordinates (naming the
  /// vertex), face indices out of range (naming the face), and meshes whose faces all have zero
  /// area. Individual degenerate faces are allowed: game meshes have them.
  void validate(const std::string& source) const;
};

}  // namespace skinlab::geometry

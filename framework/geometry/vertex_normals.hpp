#pragma once
/// \file
/// Area-weighted vertex normals: n_v = normalise(Σ over faces f ∋ v of (b − a) × (c − a)), the
/// face's cross product being twice its area times its unit normal, so large faces count more.
/// The winding decides the sign (right-hand rule on F's vertex order); call `orient_outward`
/// first when the normals must point outwards. A vertex on no face, or whose face normals
/// cancel (sum shorter than 1e-12), gets the zero vector.

#include <Eigen/Core>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

/// #V×3 unit (or zero) normals of `mesh`'s vertices. Requires valid face indices.
Eigen::MatrixXd vertex_normals(const Mesh& mesh);

}  // namespace skinlab::geometry

#pragma once
/// \file
/// Per-vertex data from a merged (or otherwise reduced) mesh back to the original vertices.

#include <Eigen/Core>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

/// Gathers rows: out.row(i) = data.row(old_to_new(i)). This is the direction used for
/// *predictions*: the network runs on the merged mesh and every original vertex at a merged
/// position receives the same result, as HeterSkinNet does (Pan et al. 2021, Sec. 4.1).
///
/// \param data        #V_new×C per-vertex values on the merged mesh (e.g. #V_new×#J weights)
/// \param old_to_new  #V_old map from merge_vertices (MergedMesh::old_to_new)
/// \return            #V_old×C
/// Throws GeometryError when an entry of old_to_new is outside [0, #V_new).
Eigen::MatrixXd gather_vertex_data(const Eigen::MatrixXd& data, const Eigen::VectorXi& old_to_new);

/// The same for sparse weights (#V_new×#J → #V_old×#J); explicit zeros are not created.
SparseWeights gather_vertex_data(const SparseWeights& data, const Eigen::VectorXi& old_to_new);

}  // namespace skinlab::geometry

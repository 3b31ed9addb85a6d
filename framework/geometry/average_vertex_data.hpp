#pragma once
/// \file
/// Per-vertex data from the original vertices onto a merged mesh.

#include <Eigen/Core>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

/// Averages the rows of all original vertices that merged into the same new vertex:
/// out.row(n) = mean{ data.row(i) : old_to_new(i) = n }. This is the direction used for
/// *training targets and input attributes* (artist weights, normals): HeterSkinNet notes that
/// duplicates at a seam carry the same skin weights (Pan et al. 2021, Sec. 4.1), so the mean
/// equals them; when an exporter left them slightly different the mean is the least-squares
/// compromise, and rows that sum to 1 still sum to 1.
///
/// \param data          #V_old×C per-vertex values on the input mesh
/// \param old_to_new    #V_old map from merge_vertices (MergedMesh::old_to_new)
/// \param num_new       #V_new, the merged mesh's vertex count
/// \return              #V_new×C
/// Throws GeometryError when sizes disagree, a map entry is outside [0, num_new), or a new
/// vertex receives no original vertex.
Eigen::MatrixXd average_vertex_data(const Eigen::MatrixXd& data, const Eigen::VectorXi& old_to_new,
                                    int num_new);

/// The same for sparse weights (#V_old×#J → #V_new×#J).
SparseWeights average_vertex_data(const SparseWeights& data, const Eigen::VectorXi& old_to_new,
                                  int num_new);

}  // namespace skinlab::geometry

#pragma once
/// \file
/// The cell grid of HollowDist (HeterSkinNet, Pan et al. 2021, Sec. 3.1, Algorithm 1 input
/// "cell grid G, side length of cell s_c") and the surface voxelisation that marks mesh cells.
///
/// Grid. The paper voxelises every character on an 88×88×88 grid (Sec. 4.1). We fit a cube of
/// R×R×R cubic cells (R = `resolution`) centred on the bounding box of mesh vertices and joints:
/// s_c = (longest bounding-box side) / (R − 2m − 1), so along the longest axis the character is
/// framed by m + ½ empty cells on each side (m = `margin_cells` ≥ 1), which lets paths go around
/// the outside, and no bounding-box face lies on a cell face. Only the central slab of that cube
/// is stored: along each shorter axis the fewest cells (same parity as R, so the slab sits on the
/// cube's lattice) that still leave ≥ m + ½ empty cells on both sides. Cutting the empty cells
/// beyond that changes no distance of Algorithm 1: clamping a 6-connected path of the cube to
/// the slab maps each step to a step or a stay, keeps hollow cells hollow (everything clamped
/// lands on the empty border layer) and never lengthens it, so every cell of the slab gets the
/// same BFS distance as in the full cube (tests/distances/hollow_dist_test.cpp checks this
/// against a full-cube reference). It makes a humanoid's grid several times smaller.
///
/// Storage. Cells are stored with one extra layer of padding on every side, flat in x-fastest
/// order, so a search can step to the 6 neighbours with constant index offsets and no bounds
/// checks (the padding is marked as "outside" by its users). Indices below are such padded
/// linear indices unless said otherwise; the order of padded indices equals the lexicographic
/// order of (z, y, x) cell coordinates, which is what ties are broken by.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "framework/geometry/mesh.hpp"
#include "framework/geometry/skeleton.hpp"

namespace skinlab::geometry {

/// Exact overlap test of a triangle and a closed axis-aligned box (separating-axis theorem over
/// the 13 axes of Akenine-Möller, "Fast 3D triangle-box overlap testing", JGT 2001): box
/// normals, triangle normal, and the 9 cross products of triangle edges with box axes. Touching
/// counts as overlap; the box is grown by 1e-9 of its size so that rounding cannot push a point
/// lying on a face shared by two cells out of both. Degenerate triangles are handled exactly: a
/// zero axis never separates, and the axes that remain are those of the segment (or point) the
/// triangle collapses to, so (a, b, b) is the segment–box test and (a, a, a) the point–box test.
bool triangle_box_overlap(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c, const Eigen::Vector3d& box_center,
                          const Eigen::Vector3d& box_half_size);

/// Geometry of the cell lattice (no contents).
class VoxelGrid {
 public:
  /// Fits the grid described in the file comment around the vertices of `mesh` and the joints
  /// of `skeleton`. Requires resolution − 2·margin_cells − 1 ≥ 1 and margin_cells ≥ 1 (checked
  /// by the options of the caller; violated here it throws GeometryError).
  static VoxelGrid fit(const Mesh& mesh, const Skeleton& skeleton, int resolution,
                       int margin_cells);

  /// The cube resolution R the grid was fitted with.
  int resolution() const { return resolution_; }
  /// Stored cells per axis (x, y, z), without padding; each ≤ R, the longest axis = R.
  const std::array<int, 3>& dims() const { return dims_; }
  /// Side s_c of a cell, in mesh units.
  double cell_size() const { return cell_size_; }
  /// Position of the lower corner of stored cell (0, 0, 0).
  const Eigen::Vector3d& origin() const { return origin_; }
  /// Offset, in cells, of stored cell (0, 0, 0) within the R×R×R cube (0 along the longest axis).
  const std::array<int, 3>& cube_offset() const { return cube_offset_; }

  /// Number of padded cells, (nx + 2)(ny + 2)(nz + 2): the length of every per-cell array.
  int num_padded() const { return static_cast<int>(stride_[2]) * (dims_[2] + 2); }
  /// Padded linear index of stored cell (i, j, k), 0 ≤ i < nx etc.
  int index(int i, int j, int k) const {
    return (i + 1) + stride_[1] * (j + 1) + stride_[2] * (k + 1);
  }
  /// Stored cell coordinates of a padded index (−1 or n along an axis for padding).
  std::array<int, 3> coords(int index) const;
  /// True for stored cells, false for the padding layer.
  bool stored(int index) const;
  /// Centre position of the cell at a padded index.
  Eigen::Vector3d center(int index) const;
  /// Padded index of the stored cell containing `p` (coordinates clamped into the grid).
  int cell_of(const Eigen::Vector3d& p) const;
  /// Index offsets to the 6 face neighbours (−x, +x, −y, +y, −z, +z).
  std::array<int, 6> neighbour_offsets() const;

  /// Padded indices of the stored cells whose closed box overlaps the triangle (a, b, c), in
  /// increasing order; only the cells of the triangle's bounding box are tested. Pass (a, b, b)
  /// for a segment and (a, a, a) for a point.
  void overlapping_cells(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c, std::vector<int>& out) const;

 private:
  int resolution_ = 0;
  std::array<int, 3> dims_{};
  std::array<int, 3> cube_offset_{};
  std::array<int, 3> stride_{};  // padded strides: 1, nx + 2, (nx + 2)(ny + 2)
  double cell_size_ = 0;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
};

/// Mesh cells of a character: the cells of `grid` whose closed box intersects a triangle
/// (HollowDist Sec. 3.1, after Schwarz and Seidel 2010: conservative surface voxelisation that
/// does not miss thin parts such as garments and hair). Computed once per character and shared
/// by the searches of all bones.
class SurfaceVoxels {
 public:
  /// Voxelises every face of `mesh` (only the cells in each face's bounding box are tested).
  /// The cell containing each vertex is also marked: it touches the vertex's faces, and marking
  /// it explicitly keeps a vertex lying within rounding error of a cell face from ending up in
  /// a cell the overlap test rejected. Requires a validated mesh.
  static SurfaceVoxels voxelize(const Mesh& mesh, VoxelGrid grid);

  const VoxelGrid& grid() const { return grid_; }
  /// True if the cell at padded index `index` is a mesh cell (false for padding).
  bool is_mesh(int index) const { return (bits_[index >> 6] >> (index & 63)) & 1u; }
  int num_mesh_cells() const { return num_mesh_cells_; }
  /// #V padded index of the cell containing each vertex.
  const std::vector<int>& vertex_cells() const { return vertex_cells_; }
  /// Bytes held (bitmask and vertex cells), for memory reports.
  std::size_t bytes() const;

 private:
  VoxelGrid grid_;
  std::vector<std::uint64_t> bits_;  // one bit per padded cell
  std::vector<int> vertex_cells_;
  int num_mesh_cells_ = 0;
};

}  // namespace skinlab::geometry

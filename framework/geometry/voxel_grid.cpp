#include "framework/geometry/voxel_grid.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <bitset>
#include <cmath>
#include <string>

namespace skinlab::geometry {

namespace {

/// Does `axis` separate the translated triangle (v0, v1, v2) from the box [−h, h]?
/// A zero axis gives p = r = 0 and never separates, which is what keeps degenerate triangles
/// exact (see triangle_box_overlap).
bool separates(const Eigen::Vector3d& axis, const Eigen::Vector3d& v0, const Eigen::Vector3d& v1,
               const Eigen::Vector3d& v2, const Eigen::Vector3d& h) {
  const double p0 = axis.dot(v0), p1 = axis.dot(v1), p2 = axis.dot(v2);
  const double r = h.dot(axis.cwiseAbs());
  return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
}

}  // namespace

bool triangle_box_overlap(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c, const Eigen::Vector3d& box_center,
                          const Eigen::Vector3d& box_half_size) {
  // Closed box, grown by 1e-9 of its size: a point on a face shared by two cells is, after
  // rounding of `p - box_center`, often outside both; now it is inside both, as exactly.
  const Eigen::Vector3d h = box_half_size * (1 + 1e-9);
  const Eigen::Vector3d v0 = a - box_center, v1 = b - box_center, v2 = c - box_center;
  // Box normals first: cheapest and the most frequent separator for the cells of a triangle's
  // bounding box.
  for (int k = 0; k < 3; ++k) {
    if (std::min({v0[k], v1[k], v2[k]}) > h[k] || std::max({v0[k], v1[k], v2[k]}) < -h[k]) {
      return false;
    }
  }
  const Eigen::Vector3d e[3] = {v1 - v0, v2 - v1, v0 - v2};
  if (separates(e[0].cross(e[1]), v0, v1, v2, h)) return false;
  for (const auto& edge : e) {
    for (int k = 0; k < 3; ++k) {
      if (separates(Eigen::Vector3d::Unit(k).cross(edge), v0, v1, v2, h)) return false;
    }
  }
  return true;
}

VoxelGrid VoxelGrid::fit(const Mesh& mesh, const Skeleton& skeleton, int resolution,
                         int margin_cells) {
  const int inner = resolution - 2 * margin_cells - 1;
  if (margin_cells < 1 || inner < 1) {
    throw GeometryError("voxel grid: resolution " + std::to_string(resolution) +
                        " leaves no cells inside a margin of " + std::to_string(margin_cells));
  }
  Eigen::Vector3d lo = mesh.V.colwise().minCoeff(), hi = mesh.V.colwise().maxCoeff();
  if (skeleton.positions.rows() > 0) {
    lo = lo.cwiseMin(skeleton.positions.colwise().minCoeff().transpose());
    hi = hi.cwiseMax(skeleton.positions.colwise().maxCoeff().transpose());
  }
  const Eigen::Vector3d extent = hi - lo;
  if (!(extent.maxCoeff() > 0) || !extent.allFinite()) {
    throw GeometryError(
        "voxel grid: the mesh and skeleton have an empty or non-finite bounding box");
  }
  VoxelGrid g;
  g.resolution_ = resolution;
  g.cell_size_ = extent.maxCoeff() / inner;
  const Eigen::Vector3d center = (lo + hi) / 2;
  for (int k = 0; k < 3; ++k) {
    int n = static_cast<int>(std::ceil(extent[k] / g.cell_size_)) + 2 * margin_cells + 1;
    if ((resolution - n) % 2 != 0) ++n;  // stay on the cube's lattice
    n = std::min(n, resolution);
    g.dims_[k] = n;
    g.cube_offset_[k] = (resolution - n) / 2;
    g.origin_[k] = center[k] - resolution * g.cell_size_ / 2 + g.cube_offset_[k] * g.cell_size_;
  }
  g.stride_ = {1, g.dims_[0] + 2, (g.dims_[0] + 2) * (g.dims_[1] + 2)};
  return g;
}

std::array<int, 3> VoxelGrid::coords(int index) const {
  const int k = index / stride_[2];
  const int rest = index - k * stride_[2];
  const int j = rest / stride_[1];
  return {rest - j * stride_[1] - 1, j - 1, k - 1};
}

bool VoxelGrid::stored(int index) const {
  const auto c = coords(index);
  for (int a = 0; a < 3; ++a) {
    if (c[a] < 0 || c[a] >= dims_[a]) return false;
  }
  return true;
}

Eigen::Vector3d VoxelGrid::center(int index) const {
  const auto c = coords(index);
  return origin_ + cell_size_ * Eigen::Vector3d(c[0] + 0.5, c[1] + 0.5, c[2] + 0.5);
}

int VoxelGrid::cell_of(const Eigen::Vector3d& p) const {
  int c[3];
  for (int a = 0; a < 3; ++a) {
    const double t = std::floor((p[a] - origin_[a]) / cell_size_);
    c[a] = static_cast<int>(std::clamp(t, 0.0, static_cast<double>(dims_[a] - 1)));
  }
  return index(c[0], c[1], c[2]);
}

std::array<int, 6> VoxelGrid::neighbour_offsets() const {
  return {-1, 1, -stride_[1], stride_[1], -stride_[2], stride_[2]};
}

void VoxelGrid::overlapping_cells(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c, std::vector<int>& out) const {
  out.clear();
  const Eigen::Vector3d lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
  int first[3], last[3];
  for (int k = 0; k < 3; ++k) {
    // The slack admits the neighbouring cell when the box touches a cell face within rounding;
    // the exact test below decides.
    const double l = std::floor((lo[k] - origin_[k]) / cell_size_ - 1e-7);
    const double h = std::floor((hi[k] - origin_[k]) / cell_size_ + 1e-7);
    first[k] = static_cast<int>(std::clamp(l, 0.0, static_cast<double>(dims_[k] - 1)));
    last[k] = static_cast<int>(std::clamp(h, 0.0, static_cast<double>(dims_[k] - 1)));
    if (h < 0 || l > dims_[k] - 1) return;  // entirely outside the grid
  }
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(cell_size_ / 2);
  for (int k = first[2]; k <= last[2]; ++k) {
    for (int j = first[1]; j <= last[1]; ++j) {
      for (int i = first[0]; i <= last[0]; ++i) {
        const Eigen::Vector3d center =
            origin_ + cell_size_ * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
        if (triangle_box_overlap(a, b, c, center, half)) out.push_back(index(i, j, k));
      }
    }
  }
}

SurfaceVoxels SurfaceVoxels::voxelize(const Mesh& mesh, VoxelGrid grid) {
  SurfaceVoxels s;
  s.grid_ = std::move(grid);
  s.bits_.assign((static_cast<std::size_t>(s.grid_.num_padded()) + 63) / 64, 0);
  auto mark = [&](int index) { s.bits_[index >> 6] |= std::uint64_t{1} << (index & 63); };
  std::vector<int> cells;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    s.grid_.overlapping_cells(mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)),
                              mesh.V.row(mesh.F(f, 2)), cells);
    for (int c : cells) mark(c);
  }
  s.vertex_cells_.resize(mesh.num_vertices());
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    s.vertex_cells_[v] = s.grid_.cell_of(mesh.V.row(v));
    mark(s.vertex_cells_[v]);
  }
  for (std::uint64_t word : s.bits_)
    s.num_mesh_cells_ += static_cast<int>(std::bitset<64>(word).count());
  return s;
}

std::size_t SurfaceVoxels::bytes() const {
  return bits_.size() * sizeof(std::uint64_t) + vertex_cells_.size() * sizeof(int);
}

}  // namespace skinlab::geometry

#include "framework/distances/hollow_dist.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "framework/core/registry.hpp"
#include "framework/geometry/closest_point_on_segment.hpp"

namespace skinlab::distances {

using geometry::GeometryError;

HollowBfs::HollowBfs(const geometry::SurfaceVoxels& voxels)
    : voxels_(&voxels), offsets_(voxels.grid().neighbour_offsets()) {
  const auto& grid = voxels.grid();
  const int n = grid.num_padded();
  steps_.assign(n, kOutside);
  const auto& d = grid.dims();
  for (int k = 0; k < d[2]; ++k)
    for (int j = 0; j < d[1]; ++j)
      for (int i = 0; i < d[0]; ++i) steps_[grid.index(i, j, k)] = kUnreached;
  phase_.assign(n, 0);
  queue_.resize(n);  // every cell is pushed at most once
}

bool HollowBfs::has_untraversed_hollow_neighbour(int cell) const {
  for (int off : offsets_) {
    const int nb = cell + off;
    if (steps_[nb] == kUnreached && !voxels_->is_mesh(nb)) return true;
  }
  return false;
}

void HollowBfs::run(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const geometry::SurfaceVoxels& vox = *voxels_;
  // Lines 2–4: only the cells the previous run reached are not at ∞ any more.
  for (int i = 0; i < tail_; ++i) steps_[queue_[i]] = kUnreached;
  int head = 0;
  tail_ = 0;
  frontier_.clear();
  heap_size_ = 0;
  restarts_ = 0;
  int mesh_left = vox.num_mesh_cells();

  // Lines 5–9: bone cells at distance 0.
  vox.grid().overlapping_cells(a, b, b, bone_cells_);
  num_bone_cells_ = static_cast<int>(bone_cells_.size());
  for (int c : bone_cells_) {
    steps_[c] = 0;
    phase_[c] = 0;
    queue_[tail_++] = c;
    if (vox.is_mesh(c)) --mesh_left;
  }

  std::int32_t phase = 0;
  while (mesh_left > 0) {  // line 10
    // Lines 11–19, stopping once the last mesh cell is reached (see the header).
    while (head < tail_ && mesh_left > 0) {
      const int c = queue_[head++];
      const std::int32_t next = steps_[c] + 1;
      const bool c_mesh = vox.is_mesh(c);
      bool blocked = false;
      for (int off : offsets_) {
        const int nb = c + off;
        if (steps_[nb] != kUnreached) continue;  // traversed, or padding (kOutside)
        const bool nb_mesh = vox.is_mesh(nb);
        if (c_mesh && !nb_mesh) {  // line 14: never leave the surface layer
          blocked = true;
          continue;
        }
        steps_[nb] = next;
        phase_[nb] = phase;
        queue_[tail_++] = nb;
        if (nb_mesh) --mesh_left;
      }
      if (blocked) frontier_.emplace_back(steps_[c], c);
    }
    if (mesh_left == 0) break;

    // Lines 20–24: restart from the untraversed hollow neighbours of the nearest mesh cell.
    // Candidates whose hollow neighbours were all reached since are dropped lazily.
    using Entry = std::pair<std::int32_t, int>;
    const auto later = std::greater<Entry>();  // min-heap on (steps, index)
    while (heap_size_ < frontier_.size()) {
      std::push_heap(frontier_.begin(), frontier_.begin() + ++heap_size_, later);
    }
    int nearest = -1;
    while (heap_size_ > 0) {
      std::pop_heap(frontier_.begin(), frontier_.begin() + heap_size_, later);
      const int c = frontier_[--heap_size_].second;
      frontier_.pop_back();
      if (has_untraversed_hollow_neighbour(c)) {
        nearest = c;
        break;
      }
    }
    if (nearest < 0) {
      // Unreachable by the argument in the header; kept so a bug cannot loop forever.
      throw GeometryError("hollow_dist: " + std::to_string(mesh_left) + " of " +
                          std::to_string(vox.num_mesh_cells()) +
                          " mesh cells unreachable and no cell to restart from (" +
                          std::to_string(num_bone_cells_) + " bone cells, " +
                          std::to_string(tail_) + " cells reached)");
    }
    ++phase;
    ++restarts_;
    for (int off : offsets_) {
      const int nb = nearest + off;
      if (steps_[nb] == kUnreached && !vox.is_mesh(nb)) {
        steps_[nb] = steps_[nearest] + 1;  // line 22
        phase_[nb] = phase;
        queue_[tail_++] = nb;
      }
    }
  }
}

void HollowBfs::vertex_distances(const geometry::Mesh& mesh, const Eigen::Vector3d& a,
                                 const Eigen::Vector3d& b, Eigen::Ref<Eigen::VectorXd> out,
                                 const std::string& bone_name) const {
  const auto& grid = voxels_->grid();
  const auto& cells = voxels_->vertex_cells();
  const double sc = grid.cell_size();
  if (static_cast<int>(cells.size()) != mesh.num_vertices() || out.size() != mesh.num_vertices()) {
    throw GeometryError("hollow_dist: mesh has " + std::to_string(mesh.num_vertices()) +
                        " vertices, the voxelised mesh " + std::to_string(cells.size()) +
                        " and the output " + std::to_string(out.size()));
  }
  // Neighbour centre = own centre + this displacement.
  const Eigen::Vector3d step[6] = {-sc * Eigen::Vector3d::UnitX(), sc * Eigen::Vector3d::UnitX(),
                                   -sc * Eigen::Vector3d::UnitY(), sc * Eigen::Vector3d::UnitY(),
                                   -sc * Eigen::Vector3d::UnitZ(), sc * Eigen::Vector3d::UnitZ()};
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const int c = cells[v];
    const std::int32_t s = steps_[c];
    const Eigen::Vector3d p = mesh.V.row(v).transpose();
    if (s == kUnreached) {
      throw GeometryError("hollow_dist: vertex " + std::to_string(v) +
                          " has no finite distance to " + bone_name +
                          " (its cell was never reached by the search)");
    }
    if (s == 0) {  // bone cell: no previous cell on the path
      out[v] = geometry::point_segment_distance(p, a, b);
      continue;
    }
    const Eigen::Vector3d center = grid.center(c);
    double best = std::numeric_limits<double>::infinity();
    for (int n = 0; n < 6; ++n) {
      const int nb = c + offsets_[n];
      if (steps_[nb] != s - 1 || phase_[nb] > phase_[c]) continue;  // not a possible c_prev
      best = std::min(best, (s - 1) * sc + (center + step[n] - p).norm());
    }
    if (!std::isfinite(best)) {
      throw GeometryError("hollow_dist: vertex " + std::to_string(v) +
                          " has no previous cell on its path to " + bone_name);
    }
    out[v] = best;
  }
}

std::size_t HollowBfs::bytes() const {
  return steps_.capacity() * sizeof(std::int32_t) + phase_.capacity() * sizeof(std::int32_t) +
         queue_.capacity() * sizeof(int) + frontier_.capacity() * sizeof(frontier_[0]) +
         bone_cells_.capacity() * sizeof(int);
}

std::string describe_bone(const geometry::Skeleton& skeleton, int bone) {
  const auto bones = skeleton.bones();
  const geometry::Bone& b = bones.at(bone);
  if (b.helper)
    return "helper bone " + std::to_string(bone) + " (at '" + skeleton.names[b.start] + "')";
  return "bone " + std::to_string(bone) + " ('" + skeleton.names[b.start] + "' -> '" +
         skeleton.names[b.end] + "')";
}

HollowDist::Options HollowDist::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "distance 'hollow_dist'");
  f.optional("resolution", o.resolution)
      .check(o.resolution >= 8, "resolution", "must be at least 8")
      .check(o.resolution <= 1024, "resolution", "must be at most 1024");
  f.optional("margin_cells", o.margin_cells)
      .check(o.margin_cells >= 1, "margin_cells", "must be at least 1")
      .check(o.resolution - 2 * o.margin_cells - 1 >= 1, "margin_cells",
             "must leave cells for the character (resolution - 2*margin_cells - 1 >= 1)");
  f.finish();
  return o;
}

geometry::SurfaceVoxels HollowDist::voxelize(const geometry::Mesh& mesh,
                                             const geometry::Skeleton& skeleton) const {
  return geometry::SurfaceVoxels::voxelize(
      mesh, geometry::VoxelGrid::fit(mesh, skeleton, options_.resolution, options_.margin_cells));
}

Eigen::MatrixXd HollowDist::compute(const geometry::Mesh& mesh,
                                    const geometry::Skeleton& skeleton) const {
  mesh.validate("hollow_dist");
  skeleton.validate("hollow_dist");
  const geometry::SurfaceVoxels voxels = voxelize(mesh, skeleton);
  const Eigen::MatrixXd segments = skeleton.bone_segments();
  const int num_bones = static_cast<int>(segments.rows());
  Eigen::MatrixXd D(mesh.num_vertices(), num_bones);
  tbb::enumerable_thread_specific<HollowBfs> workers([&] { return HollowBfs(voxels); });
  tbb::parallel_for(tbb::blocked_range<int>(0, num_bones), [&](const tbb::blocked_range<int>& r) {
    HollowBfs& bfs = workers.local();
    for (int b = r.begin(); b < r.end(); ++b) {
      const Eigen::Vector3d start = segments.row(b).head<3>(), end = segments.row(b).tail<3>();
      bfs.run(start, end);
      bfs.vertex_distances(mesh, start, end, D.col(b), describe_bone(skeleton, b));
    }
  });
  return D;
}

}  // namespace skinlab::distances

SKINLAB_REGISTER(distance, hollow_dist, skinlab::distances::HollowDist);

#pragma once
/// \file
/// `hollow_dist`: HollowDist of HeterSkinNet (Pan et al., I3D 2021, Sec. 3.1, Algorithm 1 and
/// Eq. 1): the length of a path from a bone to a vertex over a cell grid that never crosses the
/// mesh surface, found by breadth-first search, with restarts for mesh parts the search cannot
/// reach. The stages are separate so they can be timed and tested one by one:
///
///   1. `geometry::VoxelGrid::fit` + `geometry::SurfaceVoxels::voxelize`: the grid and its mesh
///      cells (once per character, shared by all bones; see voxel_grid.hpp);
///   2. `HollowBfs::run`: Algorithm 1 for one bone (lines 2–25);
///   3. `HollowBfs::vertex_distances`: Eq. 1 for every vertex and that bone.
///
/// Search. Cells are 6-connected (face neighbours, unit step s_c). The paper says only
/// "neighboring cells"; 6-connectivity is the reading under which a surface voxelised one cell
/// thick is a wall: with 18 or 26 neighbours a path steps diagonally between two hollow cells
/// across a wall whose mesh cells touch only at an edge or corner, i.e. through the surface.
/// A step from a mesh cell into a non-mesh cell is forbidden (line 14), so a path may enter the
/// surface layer and travel along it but never leaves it: it never crosses the surface.
///
/// Ambiguities of Algorithm 1 and how we resolve them:
/// - Line 6, "cells intersecting with bone b_i": cells whose closed box meets the bone segment
///   (a point for a helper bone). Bone cells may be mesh cells (a bone crossing or outside the
///   surface); they start at distance 0 like the others and obey line 14 when expanded.
/// - Line 10 loops while an untraversed mesh cell exists, testing only after the queue empties
///   (line 11). We stop the search as soon as the last mesh cell is reached: every cell that
///   Eq. 1 will read (mesh cells, and their neighbours one step closer) is then final, because
///   a BFS level is complete before the next begins. Hollow cells beyond get no distance, which
///   the output of Algorithm 1 ("distance between each bone and mesh cells") does not include.
///   Read literally, lines 20–24 also run once more after the queue empties with every mesh
///   cell reached (the test is on line 10, after the restart); that only labels hollow cells of
///   a new phase, which Eq. 1 never reads (see below), so we skip it. The reference in the tests
///   runs the literal version and agrees.
/// - Line 13, "untraversed": a cell whose distance is still ∞; bone cells are traversed from
///   the start, and a cell is labelled when pushed, so it is pushed at most once.
/// - Line 20, "the nearest mesh cell c_i neighboring to any untraversed hollow cell": "nearest"
///   is the smallest distance d_{c_i} (to the bone), among traversed mesh cells (untraversed
///   ones have d = ∞); ties go to the smallest (z, y, x) cell coordinates, so results do not
///   depend on the queue order. The text says the search restarts "from one of its neighboring
///   untraversed hollow cells" while lines 21–24 push all of them; we follow the algorithm and
///   push all, each with d_{c_i} + s_c (line 22; the subscripts are garbled in the extraction).
///   Such a cell always exists while mesh cells are untraversed: the boundary of the traversed
///   region consists of mesh cells facing untraversed hollow cells (a traversed hollow cell
///   would have expanded into any untraversed neighbour, a mesh cell into a mesh neighbour).
/// - Eq. 1, "c_prev is the cell neighboring to c, which is the previous cell on the path":
///   the BFS parent. Several neighbours are usually equally good parents (distance d_c − s_c,
///   traversed no later than c, i.e. in the same restart phase); which one the queue took
///   first is an accident of the traversal order, so we take the one that minimises Eq. 1, i.e.
///   the one whose centre is closest to the vertex. Neighbours of a later restart phase can
///   be closer to the bone, but they were reached after c and are not on its path, so they are
///   excluded. If v's own cell is a bone cell (d_c = 0, no previous cell), D is the Euclidean
///   distance from v to the bone.
/// - Every vertex's cell is a mesh cell (see SurfaceVoxels::voxelize), so the restarts give it
///   a finite distance; a vertex left without one is a GeometryError naming vertex and bone.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/distances/distance.hpp"
#include "framework/geometry/voxel_grid.hpp"

namespace skinlab::distances {

/// Algorithm 1 for one bone at a time over a shared `SurfaceVoxels`, with buffers reused from
/// bone to bone (one instance per thread). Cell distances are kept as integer step counts: every
/// distance of Algorithm 1 is a multiple of s_c.
class HollowBfs {
 public:
  /// Step count of a cell the search has not reached (d = ∞).
  static constexpr std::int32_t kUnreached = INT32_MAX;
  /// Step count of the padding layer, which the search never enters.
  static constexpr std::int32_t kOutside = -1;

  /// Keeps a reference to `voxels`, which must outlive this object.
  explicit HollowBfs(const geometry::SurfaceVoxels& voxels);

  /// Algorithm 1 (lines 2–25) for the bone segment [a, b] (a == b for a helper bone), mesh units.
  void run(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

  /// Distance of the cell at padded index `index` in steps of s_c after `run`: 0 for bone cells,
  /// kUnreached for cells not (yet) reached; final for every mesh cell.
  std::int32_t steps(int index) const { return steps_[index]; }
  /// Restart phase in which a reached cell was traversed: 0 from the bone cells, p after the p-th
  /// restart (lines 20–24).
  std::int32_t phase(int index) const { return phase_[index]; }
  /// Number of restarts of the last `run`.
  int restarts() const { return restarts_; }
  /// Number of bone cells of the last `run` (line 6).
  int num_bone_cells() const { return num_bone_cells_; }

  /// Eq. 1 for every vertex of `mesh` (the mesh that was voxelised) and the bone [a, b] of the
  /// last `run`: out(v) = d_{c_prev} + ‖p_{c_prev} − p_v‖ (#V, mesh units), or the Euclidean
  /// distance to the bone when v's cell is a bone cell. Throws GeometryError naming the vertex
  /// and `bone_name` if a vertex's cell was not reached.
  void vertex_distances(const geometry::Mesh& mesh, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b, Eigen::Ref<Eigen::VectorXd> out,
                        const std::string& bone_name) const;

  /// Bytes of the per-bone buffers (for memory reports).
  std::size_t bytes() const;

 private:
  bool has_untraversed_hollow_neighbour(int cell) const;

  const geometry::SurfaceVoxels* voxels_;
  std::array<int, 6> offsets_;
  std::vector<std::int32_t> steps_;  // per padded cell
  std::vector<std::int32_t> phase_;  // per padded cell; meaningful where steps_ is finite
  std::vector<int> queue_;           // FIFO; [0, tail_) lists every cell reached by the last run
  int tail_ = 0;
  // Traversed mesh cells that faced an untraversed hollow cell when expanded: the candidates of
  // line 20, as a min-heap on (steps, index) over [0, heap_size_) plus not yet heaped entries.
  std::vector<std::pair<std::int32_t, int>> frontier_;
  std::size_t heap_size_ = 0;
  std::vector<int> bone_cells_;
  int restarts_ = 0;
  int num_bone_cells_ = 0;
};

class HollowDist final : public Distance {
 public:
  struct Options {
    int resolution = 88;   ///< cells along the longest axis of the R×R×R cube (Sec. 4.1: 88)
    int margin_cells = 2;  ///< empty cells (plus ½) around the character, ≥ 1
    static Options from(const config::Node& node);
  };
  explicit HollowDist(Options options) : options_(options) {}

  /// #V×#B HollowDist in mesh units, bones in `Skeleton::bones()` order. Voxelises once, then
  /// runs one search per bone in parallel (TBB, one HollowBfs per thread). Validates the mesh
  /// and the skeleton first; a vertex without a finite distance is a GeometryError.
  Eigen::MatrixXd compute(const geometry::Mesh& mesh,
                          const geometry::Skeleton& skeleton) const override;

  /// Stage 1 of `compute`, exposed for benchmarks and tests.
  geometry::SurfaceVoxels voxelize(const geometry::Mesh& mesh,
                                   const geometry::Skeleton& skeleton) const;

  const Options& options() const { return options_; }

 private:
  Options options_;
};

/// "bone 3 ('spine' -> 'neck')" or "helper bone 7 (at 'head')", for error messages.
std::string describe_bone(const geometry::Skeleton& skeleton, int bone);

}  // namespace skinlab::distances

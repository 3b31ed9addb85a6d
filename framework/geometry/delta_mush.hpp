#pragma once
/// \file
/// Delta Mush (Mancewicz, Derksen, Rijpkema, Wilson, "Delta Mush: smoothing deformations while
/// preserving detail", DigiPro 2014): the corrective deformer productions put after linear blend
/// skinning. It is the non-linear target of our DenseGATs task (DenseGATs, Li et al.
/// I3D 2020, Sec. 3, learns h(G) = target − t(S) over LBS): the paper's artist-refined meshes
/// are private, and Delta Mush over the artist's own LBS is what a rigger would apply to them.
/// It is a deformer, not artist data, and experiments/densegats/README.md and the dataset card say so.
///
/// The method (Mancewicz et al. Sec. 2–3):
/// 1. Smooth the rest mesh V with `iterations` steps of Laplacian smoothing,
///        s_i ← (1 − λ) s_i + λ · mean_{j ∈ N(i)} s_j          (uniform weights, λ = `step`),
///    giving S(V); smoothing removes the detail but keeps the shape's large-scale layout.
/// 2. Store each vertex's detail δ_i = v_i − S(V)_i in a local frame of the smoothed rest mesh,
///        δ̂_i = F_iᵀ δ_i,   F_i = [t_i  b_i  n_i],
///    n_i the area-weighted normal of S(V) at i, t_i the edge to a fixed neighbour projected
///    onto the plane ⊥ n_i and normalised, b_i = n_i × t_i.
/// 3. For a deformed mesh P (the LBS result, same connectivity), smooth it the same way and put
///    the detail back in the frames of the smoothed deformed mesh:
///        out_i = S(P)_i + F_i(S(P)) δ̂_i.
///
/// Properties the tests check: P = V gives V back (to rounding); smoothing and the frames
/// commute with rigid motions, so a rigid motion of a connected part moves its Delta Mush result
/// rigidly, and a vertex whose `iterations`-ring neighbourhood moves rigidly under LBS gets
/// exactly the LBS position. Near a joint it differs from LBS: the smoothed deformed mesh
/// blends the bones' motions over the neighbourhood, so the creases, folds and kinks of the
/// skinning are spread out, and the re-applied detail restores the surface's shape on top of
/// it. It does not restore volume that the blend loses at large scale (a twisted forearm's
/// smoothed mesh is as thin as its LBS mesh).
///
/// Our choices where the paper leaves them open:
/// - uniform (graph) smoothing weights, as the paper's implementation does; they depend only on
///   connectivity, so game meshes' needle triangles do not matter (laplacian.hpp explains the
///   same choice for HeterSkinNet's smoothing term);
/// - t_i uses the neighbour whose edge, projected onto the rest tangent plane, is longest (the
///   most stable direction), and the same neighbour in every deformed mesh;
/// - a vertex without a usable frame in the smoothed rest mesh (on no face, on faces whose
///   normals cancel, or with every edge parallel to its normal) keeps its LBS position, as does
///   a vertex whose frame degenerates in the smoothed deformed mesh. Such vertices are counted
///   (`passthrough()`), never silently mixed in.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

struct DeltaMushOptions {
  int iterations = 10;  ///< smoothing steps, ≥ 1 (the reach of the correction, in rings)
  double step = 0.5;    ///< λ in (0, 1]
};

class DeltaMush {
 public:
  /// Precomputes the smoothing operator, the rest frames and the rest details of `rest` (#V×3,
  /// #F×3). Throws GeometryError for an invalid mesh (Mesh::validate, prefixed by `source`) and
  /// for iterations < 1 or a step outside (0, 1].
  DeltaMush(const Mesh& rest, const DeltaMushOptions& options = {},
            const std::string& source = "delta_mush");

  /// The Delta Mush result for `posed` (#V×3: the rest mesh's vertices deformed, e.g. by lbs()).
  /// Throws GeometryError naming the source if posed is not #V×3 or has a non-finite coordinate
  /// (naming the vertex). `passthrough`, when given, receives the number of vertices that kept
  /// their posed position because their frame was unusable.
  Eigen::MatrixXd deform(const Eigen::MatrixXd& posed, int* passthrough = nullptr) const;

  /// Vertices without a usable rest frame (they always keep their posed position).
  int passthrough() const { return rest_passthrough_; }
  int num_vertices() const { return static_cast<int>(detail_.rows()); }

 private:
  Eigen::MatrixXd smooth(const Eigen::MatrixXd& X) const;

  DeltaMushOptions options_;
  std::string source_;
  Eigen::MatrixXi faces_;
  std::vector<std::vector<int>> neighbours_;
  std::vector<int> tangent_neighbour_;  ///< −1: no usable rest frame
  Eigen::MatrixXd detail_;              ///< #V×3 δ̂ in the rest frames
  int rest_passthrough_ = 0;
};

}  // namespace skinlab::geometry

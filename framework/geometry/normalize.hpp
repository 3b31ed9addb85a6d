#pragma once
/// \file
/// Normalisation of a character as in RigNet's dataset (Xu et al., SIGGRAPH 2020, and
/// its quick_start/gen_dataset scripts): consistent orientation (Y up), scaled to unit height,
/// centred. The applied similarity is returned so that predictions (joint positions,
/// deformations) can be mapped back to the source frame and units.
///
/// Convention (state it once, use it everywhere): after normalisation the mesh's axis-aligned
/// bounding box has Y extent 1 (so a character authored in metres becomes 1 m tall), its centre
/// in x and z is at 0, and its lowest point (the feet) is at y = 0. RigNet's normalisation
/// pivot, as we read its quick_start.py (normalize_obj), is the same point (x/z centre of the
/// box, lowest y), but it divides by the largest box extent; we divide by the Y extent so that
/// every character is exactly 1 tall whatever its arm span.

#include <Eigen/Core>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

/// x ↦ scale · rotation · x + translation, with scale > 0 and rotation a proper rotation.
struct Similarity {
  double scale = 1.0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  /// Applies the map to the rows of P (#P×3 points) and returns #P×3 points.
  Eigen::MatrixXd apply(const Eigen::MatrixXd& P) const;
  /// The inverse map: x ↦ (1/scale) · rotationᵀ · (x − translation).
  Similarity inverse() const;
  /// (*this ∘ first)(x) = (*this)(first(x)).
  Similarity after(const Similarity& first) const;
  /// The 4×4 homogeneous matrix [scale·rotation, translation; 0 0 0 1].
  Eigen::Matrix4d matrix() const;
};

struct NormalizeOptions {
  /// The up direction of the source frame (need not be unit length). Y for B3D, glTF, COLLADA
  /// after assimp's own axis conversion; an FBX file's declared axis is in
  /// ImportReport::source_up. The rotation is the smallest one taking source_up to +Y (for
  /// +Z up: (x, y, z) ↦ (x, z, −y), Blender's convention), or 180° about X if source_up is −Y.
  Eigen::Vector3d source_up = Eigen::Vector3d::UnitY();
  double height = 1.0;  ///< target bounding-box Y extent, in the output units (metres)
};

/// Rotates, scales and translates the character's mesh V (#V×3) and joint positions (#J×3) in
/// place as described in the file comment, and returns the similarity applied (source frame →
/// normalised frame); `.inverse().apply(...)` maps normalised results back. Weights and
/// connectivity are unchanged. Throws GeometryError, naming the character, if source_up is zero
/// or not finite, or the mesh has zero height along the up axis.
Similarity normalize(Character& character, const NormalizeOptions& options = {});

}  // namespace skinlab::geometry

#pragma once
/// \file
/// ACAP deformation features of a fixed-connectivity mesh sequence, the representation of the
/// mesh-sequence BiLSTM (Qiao et al., "Synthesizing Mesh Deformation Sequences with
/// Bidirectional LSTM", Sec. 3.1, Eq. 1) after Gao et al. 2019 ("Sparse Data Driven Mesh
/// Deformation", the as-consistent-as-possible representation).
///
/// Encoding, per frame t and vertex i, with respect to the template (the sequence's first
/// frame, Sec. 3.1):
///  1. The deformation gradient (Eq. 1) T_i = argmin_T Σ_{j∈N_i} c_ij |e'_ij − T e_ij|² with
///     e_ij = p_i − p_j on the template, e'_ij on frame t, and c_ij the cotangent weight of edge
///     ij. A one-ring on a surface is nearly planar, so Σ c e eᵀ is (nearly) rank 2 and the
///     fit does not say where the normal goes; as Sumner and Popović's fourth vertex does for a
///     triangle, we add the vertex normal scaled by the one-ring's mean edge length as one more
///     "edge" with the one-ring's mean weight: n_i ℓ_i ↦ n'_i ℓ'_i. Rigid motions and uniform
///     scalings are then recovered exactly. Where the face normals cancel (a double-sided
///     sheet, common in game meshes) the one-ring's best-fit plane normal is used, with the
///     sign that keeps det T > 0. A prior μ |T − I|² with μ = 10⁻⁹ tr(Σ c e eᵀ + …) settles
///     anything still open.
///  2. Polar decomposition T_i = R_i S_i (R_i a rotation, S_i symmetric; via the SVD).
///  3. R_i as a rotation vector r_i = θ_i ω_i. The same rotation is every (θ_i + 2πk) ω_i, k ∈ ℤ
///     (a negative multiplier is the opposite axis); ACAP picks, for every vertex, the
///     representative most consistent with the rest. Gao et al. solve a global integer program
///     over the mesh; we choose per vertex the representative nearest to a reference vector:
///     in a sequence, the same vertex's vector in the previous frame (the template's is 0,
///     since its rotations are the identity), so a joint twisting past π keeps a continuous
///     angle; for a single mesh (`encode`), the mean of the vertex's already-assigned one-ring
///     neighbours in breadth-first order from the vertex of least rotation.
///  4. The feature q_i ∈ ℝ⁹: r_i and the six distinct entries of S_i
///     (S_00, S_01, S_02, S_11, S_12, S_22).
///
/// Decoding (Gao et al. Sec. 3; what `decode` does): T_i = exp([r_i]×) S_i, then the positions
/// minimising Σ_i Σ_{j∈N_i} c_ij |(p_i − p_j) − T_i (q_i − q_j)|², the Poisson system
/// L p = b, b_i = ½ Σ_j c_ij (T_i + T_j)(q_i − q_j), with L the cotangent Laplacian. Translation
/// is free per connected part: each part's centroid is put where the caller says (by default,
/// the template's).
///
/// Weights: c_ij = ½ (cot α + cot β) over the triangles at the edge (laplacian.hpp), floored
/// at `min_weight` so that obtuse triangles cannot make the system indefinite and every mesh
/// edge keeps its part connected.
///
/// `FeatureScale` is the linear map of every feature dimension into [−0.95, 0.95] over a data
/// set (Sec. 3.1, following Tan et al.'s mesh VAE) and back.

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <memory>
#include <vector>

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

/// Features per vertex: 3 rotation-vector components and 6 of the symmetric scale.
inline constexpr int kAcapWidth = 9;

struct AcapOptions {
  /// Floor of the cotangent edge weights (cotangents are dimensionless; an equilateral
  /// triangle's edge gets ½ cot 60° ≈ 0.29 from each side).
  double min_weight = 1e-2;
};

/// The polar decomposition T = R S (R a rotation, S symmetric positive semi-definite) via the
/// SVD T = U Σ Vᵀ: R = U Vᵀ with the sign of U's last column flipped when det(U Vᵀ) < 0 (then S
/// has one negative eigenvalue: a reflection is kept in S, never in R).
void polar_decompose(const Eigen::Matrix3d& T, Eigen::Matrix3d& R, Eigen::Matrix3d& S);

/// exp([r]×): the rotation by |r| about r / |r| (identity for r = 0), for any |r|.
Eigen::Matrix3d rotation_of(const Eigen::Vector3d& r);

/// The representative (θ + 2πk) ω of rotation vector `r` (θ = |r|, ω = r / θ; any k ∈ ℤ)
/// nearest to `reference`. r = 0 is returned as is.
Eigen::Vector3d nearest_rotation_vector(const Eigen::Vector3d& r, const Eigen::Vector3d& reference);

class AcapEncoder {
 public:
  /// Precomputes the template's edge weights, scaled normals, the fit's Gram matrices and the
  /// factorised Poisson system. Throws GeometryError (prefixed by `source`) for an invalid mesh
  /// or a vertex on no edge (naming it).
  AcapEncoder(const Mesh& reference, const std::string& source, AcapOptions options = {});
  ~AcapEncoder();
  AcapEncoder(AcapEncoder&&) noexcept;
  AcapEncoder& operator=(AcapEncoder&&) noexcept;

  int num_vertices() const { return static_cast<int>(reference_.V.rows()); }
  const Mesh& reference() const { return reference_; }

  /// #V deformation gradients of `deformed` (#V×3, the template's connectivity) w.r.t. the
  /// template (Eq. 1 with the normal term of the file comment). Throws GeometryError for a
  /// wrong size or non-finite coordinates (naming the vertex).
  std::vector<Eigen::Matrix3d> deformation_gradients(const Eigen::MatrixXd& deformed) const;

  /// #V×9 features of one mesh, rotation vectors made consistent over the mesh (file comment).
  Eigen::MatrixXd encode(const Eigen::MatrixXd& deformed) const;

  /// #V×9 features of every frame, each vertex's rotation vector consistent with its vector in
  /// the previous frame (the template's rotation vectors are 0).
  std::vector<Eigen::MatrixXd> encode_sequence(const std::vector<Eigen::MatrixXd>& frames) const;

  /// The mesh (#V×3) of `features` (#V×9), each connected part's centroid at its centroid in
  /// the template. Throws GeometryError for a wrong size or a non-finite feature (naming the
  /// vertex).
  Eigen::MatrixXd decode(const Eigen::MatrixXd& features) const;
  /// As `decode`, each connected part's centroid at the centroid of its vertices in `placement`
  /// (#V×3: e.g. the frame being reconstructed, or the previous frame).
  Eigen::MatrixXd decode(const Eigen::MatrixXd& features, const Eigen::MatrixXd& placement) const;

  /// Connected part of every vertex (0-based, in order of first vertex) and their count.
  const std::vector<int>& parts() const { return part_; }
  int num_parts() const { return num_parts_; }

 private:
  Eigen::Matrix3d fit(int i, const Eigen::MatrixXd& deformed, const Eigen::MatrixXd& normals) const;
  /// T = exp([r]×) S with r the principal rotation vector (angle in [0, π]).
  struct Polar {
    Eigen::Vector3d r;
    Eigen::Matrix3d S;
  };
  static Polar polar_of(const Eigen::Matrix3d& T);
  /// The feature of one vertex: r's representative nearest `reference`, and S.
  static Eigen::RowVectorXd feature_of(const Polar& p, const Eigen::Vector3d& reference);
  void check_frame(const Eigen::MatrixXd& X, int width, const char* what) const;

  Mesh reference_;
  std::string source_;
  AcapOptions options_;
  /// One-ring of every vertex: neighbour and weight c_ij, sorted by neighbour.
  std::vector<std::vector<std::pair<int, double>>> ring_;
  std::vector<double> mean_weight_;                ///< c̄ per vertex, on the template
  Eigen::MatrixXd normals_;                        ///< template's length-scaled vertex normals
  std::vector<char> flat_;                         ///< template normal from the one-ring plane
  std::vector<Eigen::Matrix3d> gram_inverse_;      ///< (Σ c e eᵀ + c̄ ℓ² n nᵀ + μ I)⁻¹ per vertex
  std::vector<double> prior_;                      ///< μ per vertex
  std::vector<int> part_;
  int num_parts_ = 0;
  std::vector<int> pinned_;  ///< one vertex per part (its first), removed from the system
  std::vector<int> unknown_;  ///< vertex → row of the reduced system, −1 if pinned
  std::unique_ptr<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>> solver_;
};

/// The linear map of every feature dimension (every vertex's every component: Tan et al.'s
/// mesh VAE, which Sec. 3.1 follows) into [−0.95, 0.95] over a data set, and back.
struct FeatureScale {
  Eigen::MatrixXd min, max;  ///< #V×D, over the fitted frames
  static constexpr double kBound = 0.95;

  /// Fits min and max of every entry over all `frames` (each #V×D, all of one shape). A
  /// constant entry maps to 0 and back to its value. Throws Error for no frames or unequal
  /// shapes (naming the frame).
  static FeatureScale fit(const std::vector<Eigen::MatrixXd>& frames);
  /// Throws Error for another shape than the fitted one.
  Eigen::MatrixXd normalise(const Eigen::MatrixXd& features) const;
  Eigen::MatrixXd denormalise(const Eigen::MatrixXd& normalised) const;
};

}  // namespace skinlab::geometry

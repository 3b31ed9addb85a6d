#pragma once
/// \file
/// Linear blend skinning (Magnenat-Thalmann et al. 1988; the form of libigl's lbs_matrix.h),
/// and the forward kinematics that turns a pose of local joint rotations into the per-joint
/// transforms it needs. Used by the deformation error metric: posed meshes under predicted and
/// artist weights are compared over random poses (random_pose).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

/// Deforms the rest mesh:  v'_i = Σ_j W(i,j) · T_j · [v_i; 1].
///
/// \param V  #V×3 rest (bind-pose) vertex positions
/// \param W  #V×#J per-joint weights (rows normally sum to 1; not renormalised here)
/// \param T  #J affine transforms, each relative to the bind pose (bind → posed, in the frame of
///           V); an Eigen::Affine3d is the 4×4 matrix, and a 3×4 [R|t] is its top three rows
///           (`T[j].matrix().topRows<3>() = M`)
/// \return   #V×3 deformed positions, in the frame of V
/// Throws GeometryError if W is not #V×#J or V is not #V×3.
Eigen::MatrixXd lbs(const Eigen::MatrixXd& V, const SparseWeights& W,
                    const std::vector<Eigen::Affine3d>& T);

/// Throws GeometryError, prefixed by `who`, unless V is #V×3 and W is #V×#J for #J = T.size():
/// the argument check of lbs and dqs.
void check_skinning_inputs(const char* who, const Eigen::MatrixXd& V, const SparseWeights& W,
                           const std::vector<Eigen::Affine3d>& T);

/// Forward kinematics about the rest joint positions: joint j rotates its own subtree by
/// `local_rotations[j]` about its rest position p_j, on top of its parent's motion,
///     T_j = T_parent(j) · Translate(p_j) · R_j · Translate(−p_j),   T_root's parent = identity.
/// Rotations are expressed in the rest frame of the skeleton (the joints carry no local
/// orientation), which is what a random test pose needs. Identity rotations give identity
/// transforms, so lbs reproduces the bind pose exactly.
///
/// \param skeleton         #J joints, positions #J×3 (the rest pose), parents
/// \param local_rotations  #J 3×3 rotation matrices
/// \return #J transforms relative to the bind pose, for lbs
/// Throws GeometryError if the counts differ.
std::vector<Eigen::Affine3d> forward_kinematics(const Skeleton& skeleton,
                                                const std::vector<Eigen::Matrix3d>& local_rotations);

/// A random pose for the deformation error metric (HeterSkinNet Sec. 4.3: "rotating 30% of bones
/// ... by angles sampled independently from N(0, 25°)"): round(fraction · #J) distinct joints,
/// chosen uniformly, are each rotated by an angle drawn from N(0, sigma_degrees²) about a
/// uniformly random axis; the others keep the identity. A joint's rotation turns every bone that
/// starts at it, so the paper's fraction of bones is taken as that fraction of the joints, and as
/// an exact count rather than a per-joint coin flip (which would leave small skeletons unposed
/// now and then).
///
/// Only the raw 32-bit output of `rng` is used (uniforms from single draws, normals by
/// Box–Muller), not std:: distributions, whose algorithms differ between standard libraries: a
/// seeded mt19937 gives the same pose with any toolchain.
///
/// Returns #J rotation matrices. Throws GeometryError unless 0 ≤ fraction ≤ 1 and
/// sigma_degrees is finite and ≥ 0.
std::vector<Eigen::Matrix3d> random_pose(const Skeleton& skeleton, std::mt19937& rng,
                                         double fraction = 0.3, double sigma_degrees = 25.0);

}  // namespace skinlab::geometry

#pragma once
/// \file
/// Dual quaternion skinning (Kavan, Collins, Žára, O'Sullivan, "Skinning with Dual Quaternions",
/// I3D 2007; DenseGATs, Li et al. I3D 2020, Sec. 2 and Fig. 10, compare their corrective
/// network with it and with linear blend skinning). Each joint's rigid transform becomes a unit
/// dual quaternion q̂_j = q_j + ε ½ t_j q_j; a vertex blends them linearly with its weights and
/// renormalises (DLB, Kavan et al. Sec. 3.3):
///
///     b̂ = Σ_j w_j s_j q̂_j,    ĉ = b̂ / ‖b_0‖,    v' = R(c_0) v + 2 (c_ε c_0*)_vec
///
/// where s_j = ±1 flips q̂_j into the hemisphere of the vertex's most-weighted joint (q and −q
/// are the same rotation; without the flip a blend can pass the long way round). A blend of
/// rotations about one centre stays a rotation about it, so DQS keeps the volume that linear
/// blending loses at a twisting or bending joint ("candy wrapper"), at the price of some bulging.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

/// Deforms the rest mesh by dual quaternion skinning, with the same arguments as lbs():
///
/// \param V  #V×3 rest (bind-pose) vertex positions
/// \param W  #V×#J per-joint weights (not renormalised; ĉ's normalisation makes the result
///           independent of a row's scale)
/// \param T  #J rigid transforms relative to the bind pose (forward_kinematics)
/// \return   #V×3 deformed positions
/// Throws GeometryError if W is not #V×#J or V is not #V×3, if a transform is not rigid (its
/// linear part is not a rotation within 1e-6; DQS has no scale or shear), naming the joint, and
/// if a vertex has no weight (nothing to blend), naming the vertex.
Eigen::MatrixXd dqs(const Eigen::MatrixXd& V, const SparseWeights& W,
                    const std::vector<Eigen::Affine3d>& T);

}  // namespace skinlab::geometry

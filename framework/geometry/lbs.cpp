#include "framework/geometry/lbs.hpp"

#include <cmath>
#include <string>

namespace skinlab::geometry {

Eigen::MatrixXd lbs(const Eigen::MatrixXd& V, const SparseWeights& W,
                    const std::vector<Eigen::Affine3d>& T) {
  if (V.cols() != 3) {
    throw GeometryError("lbs: V must be #V×3, got " + std::to_string(V.cols()) + " columns");
  }
  if (W.rows() != V.rows() || W.cols() != static_cast<Eigen::Index>(T.size())) {
    throw GeometryError("lbs: weights are " + std::to_string(W.rows()) + "×" +
                        std::to_string(W.cols()) + ", expected #V×#J = " +
                        std::to_string(V.rows()) + "×" + std::to_string(T.size()));
  }
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(V.rows(), 3);
  for (Eigen::Index i = 0; i < W.outerSize(); ++i) {
    const Eigen::Vector3d v = V.row(i).transpose();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (SparseWeights::InnerIterator it(W, i); it; ++it) sum += it.value() * (T[it.col()] * v);
    out.row(i) = sum.transpose();
  }
  return out;
}

std::vector<Eigen::Affine3d> forward_kinematics(const Skeleton& skeleton,
                                                const std::vector<Eigen::Matrix3d>& local_rotations) {
  const int n = skeleton.num_joints();
  if (static_cast<int>(local_rotations.size()) != n) {
    throw GeometryError("forward_kinematics: " + std::to_string(local_rotations.size()) +
                        " rotations for " + std::to_string(n) + " joints");
  }
  std::vector<Eigen::Affine3d> T(n);
  std::vector<bool> done(n, false);
  // Parents may come after children in an arbitrary Skeleton, so resolve chains on demand.
  for (int j = 0; j < n; ++j) {
    std::vector<int> chain;
    for (int k = j; k >= 0 && !done[k]; k = skeleton.parents[k]) chain.push_back(k);
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const int k = *it;
      const Eigen::Vector3d p = skeleton.positions.row(k).transpose();
      Eigen::Affine3d local = Eigen::Translation3d(p) * Eigen::Affine3d(local_rotations[k]) *
                              Eigen::Translation3d(-p);
      const int parent = skeleton.parents[k];
      T[k] = parent >= 0 ? T[parent] * local : local;
      done[k] = true;
    }
  }
  return T;
}

std::vector<Eigen::Matrix3d> random_pose(const Skeleton& skeleton, std::mt19937& rng,
                                         double fraction, double sigma_degrees) {
  std::bernoulli_distribution pick(fraction);
  std::normal_distribution<double> angle(0.0, sigma_degrees * M_PI / 180.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<Eigen::Matrix3d> R(skeleton.num_joints(), Eigen::Matrix3d::Identity());
  for (auto& r : R) {
    if (!pick(rng)) continue;
    Eigen::Vector3d axis;
    do {  // a normalised Gaussian vector is uniform on the sphere
      axis = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    } while (axis.norm() < 1e-9);
    r = Eigen::AngleAxisd(angle(rng), axis.normalized()).toRotationMatrix();
  }
  return R;
}

}  // namespace skinlab::geometry

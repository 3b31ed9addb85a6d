#include "framework/geometry/lbs.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "framework/core/stable_random.hpp"

namespace skinlab::geometry {

void check_skinning_inputs(const char* who, const Eigen::MatrixXd& V, const SparseWeights& W,
                           const std::vector<Eigen::Affine3d>& T) {
  if (V.cols() != 3) {
    throw GeometryError(std::string(who) + ": V must be #V×3, got " + std::to_string(V.cols()) +
                        " columns");
  }
  if (W.rows() != V.rows() || W.cols() != static_cast<Eigen::Index>(T.size())) {
    throw GeometryError(std::string(who) + ": weights are " + std::to_string(W.rows()) + "×" +
                        std::to_string(W.cols()) + ", expected #V×#J = " +
                        std::to_string(V.rows()) + "×" + std::to_string(T.size()));
  }
}

Eigen::MatrixXd lbs(const Eigen::MatrixXd& V, const SparseWeights& W,
                    const std::vector<Eigen::Affine3d>& T) {
  check_skinning_inputs("lbs", V, W, T);
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
  if (!(fraction >= 0 && fraction <= 1)) {
    throw GeometryError("random_pose: fraction must be in [0, 1], got " + std::to_string(fraction));
  }
  if (!(sigma_degrees >= 0) || !std::isfinite(sigma_degrees)) {
    throw GeometryError("random_pose: sigma_degrees must be finite and ≥ 0, got " +
                        std::to_string(sigma_degrees));
  }
  const int n = skeleton.num_joints();
  const int k = static_cast<int>(std::lround(fraction * n));
  // The first k entries of a partial Fisher–Yates shuffle are a uniform k-subset.
  std::vector<int> order(n);
  for (int j = 0; j < n; ++j) order[j] = j;
  for (int i = 0; i < k; ++i) {
    const int pick = std::min(n - 1, i + static_cast<int>(uniform_open(rng) * (n - i)));
    std::swap(order[i], order[pick]);
  }
  std::vector<bool> rotated(n, false);
  for (int i = 0; i < k; ++i) rotated[order[i]] = true;

  const double sigma = sigma_degrees * M_PI / 180.0;
  std::vector<Eigen::Matrix3d> R(n, Eigen::Matrix3d::Identity());
  for (int j = 0; j < n; ++j) {  // index order, so the draws do not depend on the shuffle order
    if (!rotated[j]) continue;
    Eigen::Vector3d axis;
    do {  // a normalised Gaussian vector is uniform on the sphere
      axis = Eigen::Vector3d(standard_normal(rng), standard_normal(rng), standard_normal(rng));
    } while (axis.norm() < 1e-9);
    R[j] = Eigen::AngleAxisd(sigma * standard_normal(rng), axis.normalized()).toRotationMatrix();
  }
  return R;
}

}  // namespace skinlab::geometry

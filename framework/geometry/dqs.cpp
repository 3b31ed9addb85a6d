#include "framework/geometry/dqs.hpp"

#include <string>

#include "framework/geometry/lbs.hpp"

namespace skinlab::geometry {

namespace {

/// A dual quaternion real + ε dual, as two 4-vectors (w, x, y, z) so that blends are linear.
struct DualQuaternion {
  Eigen::Vector4d real = Eigen::Vector4d::Zero();
  Eigen::Vector4d dual = Eigen::Vector4d::Zero();
};

Eigen::Vector4d as_vector(const Eigen::Quaterniond& q) { return {q.w(), q.x(), q.y(), q.z()}; }
Eigen::Quaterniond as_quaternion(const Eigen::Vector4d& v) {
  return Eigen::Quaterniond(v(0), v(1), v(2), v(3));
}

DualQuaternion from_rigid(const Eigen::Affine3d& t, int joint) {
  const Eigen::Matrix3d r = t.linear();
  if (!(r * r.transpose()).isIdentity(1e-6) || r.determinant() < 0) {
    throw GeometryError("dqs: the transform of joint " + std::to_string(joint) +
                        " is not rigid (its linear part is not a rotation)");
  }
  const Eigen::Quaterniond q(r);
  const Eigen::Vector3d d = t.translation();
  const Eigen::Quaterniond translation(0, d.x(), d.y(), d.z());
  DualQuaternion out;
  out.real = as_vector(q);
  out.dual = 0.5 * as_vector(translation * q);
  return out;
}

}  // namespace

Eigen::MatrixXd dqs(const Eigen::MatrixXd& V, const SparseWeights& W,
                    const std::vector<Eigen::Affine3d>& T) {
  check_skinning_inputs("dqs", V, W, T);
  std::vector<DualQuaternion> q;
  q.reserve(T.size());
  for (std::size_t j = 0; j < T.size(); ++j) q.push_back(from_rigid(T[j], static_cast<int>(j)));

  Eigen::MatrixXd out(V.rows(), 3);
  for (Eigen::Index i = 0; i < W.outerSize(); ++i) {
    // The pivot: the most-weighted joint (the first of equals).
    Eigen::Index pivot = -1;
    double most = 0;
    for (SparseWeights::InnerIterator it(W, i); it; ++it) {
      if (it.value() > most) {
        most = it.value();
        pivot = it.col();
      }
    }
    if (pivot < 0) {
      throw GeometryError("dqs: vertex " + std::to_string(i) + " has no weight");
    }
    DualQuaternion b;
    for (SparseWeights::InnerIterator it(W, i); it; ++it) {
      const DualQuaternion& qj = q[static_cast<std::size_t>(it.col())];
      const double s = qj.real.dot(q[static_cast<std::size_t>(pivot)].real) < 0 ? -1.0 : 1.0;
      b.real += s * it.value() * qj.real;
      b.dual += s * it.value() * qj.dual;
    }
    const double norm = b.real.norm();
    const Eigen::Quaterniond c0 = as_quaternion(b.real / norm);
    const Eigen::Quaterniond ce = as_quaternion(b.dual / norm);
    const Eigen::Vector3d t = 2.0 * (ce * c0.conjugate()).vec();
    out.row(i) = (c0.toRotationMatrix() * V.row(i).transpose() + t).transpose();
  }
  return out;
}

}  // namespace skinlab::geometry

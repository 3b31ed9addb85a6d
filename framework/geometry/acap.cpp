#include "framework/geometry/acap.hpp"

#include <Eigen/Geometry>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <deque>
#include <numeric>
#include <string>

#include "framework/core/error.hpp"
#include "framework/geometry/laplacian.hpp"
#include "framework/geometry/vertex_normals.hpp"

namespace skinlab::geometry {

namespace {

constexpr double kTwoPi = 2 * M_PI;
/// Weight of the identity prior of the fit, relative to the trace of the one-ring's Gram matrix.
constexpr double kPrior = 1e-9;

/// Unit normals of `V` on the template's faces, each scaled by the vertex's mean one-ring edge
/// length in `V`. Where the face normals cancel (a double-sided sheet: both windings share the
/// vertices), the normal of the one-ring's best-fitting plane instead, its sign left open
/// (`flat` marks those vertices; `AcapEncoder::fit` picks the sign).
Eigen::MatrixXd scaled_normals(const Eigen::MatrixXi& F, const Eigen::MatrixXd& V,
                               const std::vector<std::vector<std::pair<int, double>>>& ring,
                               std::vector<char>* flat = nullptr) {
  Mesh m;
  m.V = V;
  m.F = F;
  Eigen::MatrixXd N = vertex_normals(m);
  if (flat) flat->assign(static_cast<std::size_t>(V.rows()), 0);
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const auto& r = ring[static_cast<std::size_t>(i)];
    double length = 0;
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const auto& [j, c] : r) {
      const Eigen::Vector3d e = (V.row(i) - V.row(j)).transpose();
      length += e.norm();
      scatter += e * e.transpose();
    }
    if (N.row(i).squaredNorm() < 0.5) {  // vertex_normals gives 0 where the normals cancel
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
      N.row(i) = eig.eigenvectors().col(0).transpose();
      if (flat) (*flat)[static_cast<std::size_t>(i)] = 1;
    }
    N.row(i) *= length / static_cast<double>(r.size());
  }
  return N;
}

}  // namespace

void polar_decompose(const Eigen::Matrix3d& T, Eigen::Matrix3d& R, Eigen::Matrix3d& S) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(T, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  Eigen::Vector3d sigma = svd.singularValues();
  if ((U * V.transpose()).determinant() < 0) {
    U.col(2) *= -1;
    sigma(2) *= -1;
  }
  R = U * V.transpose();
  S = V * sigma.asDiagonal() * V.transpose();
  S = 0.5 * (S + S.transpose());
}

Eigen::Matrix3d rotation_of(const Eigen::Vector3d& r) {
  const double theta = r.norm();
  if (theta == 0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(theta, r / theta).toRotationMatrix();
}

Eigen::Vector3d nearest_rotation_vector(const Eigen::Vector3d& r, const Eigen::Vector3d& reference) {
  const double theta = r.norm();
  if (theta == 0) return r;
  const Eigen::Vector3d axis = r / theta;
  // |(θ + 2πk) ω − ref|² is a parabola in k with its minimum at (ω·ref − θ) / 2π.
  const double k0 = std::round((axis.dot(reference) - theta) / kTwoPi);
  Eigen::Vector3d best = r;
  double best_distance = std::numeric_limits<double>::infinity();
  for (double k = k0 - 1; k <= k0 + 1; ++k) {
    const Eigen::Vector3d candidate = (theta + kTwoPi * k) * axis;
    const double d = (candidate - reference).squaredNorm();
    if (d < best_distance) {
      best_distance = d;
      best = candidate;
    }
  }
  return best;
}

AcapEncoder::AcapEncoder(const Mesh& reference, const std::string& source, AcapOptions options)
    : reference_(reference), source_(source), options_(options) {
  reference_.validate(source_);
  if (!(options_.min_weight > 0) || !std::isfinite(options_.min_weight)) {
    throw GeometryError(source_ + ": ACAP min_weight must be positive and finite");
  }
  const int n = num_vertices();
  LaplacianOptions lo;
  lo.kind = LaplacianKind::kCotangent;
  const Eigen::SparseMatrix<double> L = laplacian(reference_, lo);
  ring_.assign(static_cast<std::size_t>(n), {});
  for (Eigen::Index f = 0; f < reference_.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = reference_.F(f, k), b = reference_.F(f, (k + 1) % 3);
      if (a == b) continue;
      const double w = std::max(-L.coeff(a, b), options_.min_weight);
      ring_[static_cast<std::size_t>(a)].emplace_back(b, w);
      ring_[static_cast<std::size_t>(b)].emplace_back(a, w);
    }
  }
  for (int i = 0; i < n; ++i) {
    auto& r = ring_[static_cast<std::size_t>(i)];
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end(),
                        [](const auto& x, const auto& y) { return x.first == y.first; }),
            r.end());
    if (r.empty()) {
      throw GeometryError(source_ + ": vertex " + std::to_string(i) +
                          " is on no edge; ACAP features need every vertex in a triangle");
    }
  }

  // Template quantities of the fit (Eq. 1 plus the normal term).
  normals_ = scaled_normals(reference_.F, reference_.V, ring_, &flat_);
  mean_weight_.resize(static_cast<std::size_t>(n));
  gram_inverse_.resize(static_cast<std::size_t>(n));
  prior_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto& r = ring_[static_cast<std::size_t>(i)];
    Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
    double wsum = 0;
    for (const auto& [j, c] : r) {
      const Eigen::Vector3d e = (reference_.V.row(i) - reference_.V.row(j)).transpose();
      G += c * e * e.transpose();
      wsum += c;
    }
    mean_weight_[static_cast<std::size_t>(i)] = wsum / static_cast<double>(r.size());
    const Eigen::Vector3d nl = normals_.row(i).transpose();
    G += mean_weight_[static_cast<std::size_t>(i)] * nl * nl.transpose();
    // The identity prior (weight μ = kPrior · tr G) decides directions the one-ring and its
    // normal leave open: a double-sided sheet's normals cancel, leaving G rank 2.
    G += kPrior * G.trace() * Eigen::Matrix3d::Identity();
    gram_inverse_[static_cast<std::size_t>(i)] = G.inverse();
    prior_[static_cast<std::size_t>(i)] = kPrior * G.trace() / (1 + 3 * kPrior);
  }

  // Connected parts, one pinned vertex each, and the reduced Poisson system.
  part_.assign(static_cast<std::size_t>(n), -1);
  for (int s = 0; s < n; ++s) {
    if (part_[static_cast<std::size_t>(s)] >= 0) continue;
    std::deque<int> queue{s};
    part_[static_cast<std::size_t>(s)] = num_parts_;
    pinned_.push_back(s);
    while (!queue.empty()) {
      const int i = queue.front();
      queue.pop_front();
      for (const auto& [j, c] : ring_[static_cast<std::size_t>(i)]) {
        if (part_[static_cast<std::size_t>(j)] < 0) {
          part_[static_cast<std::size_t>(j)] = num_parts_;
          queue.push_back(j);
        }
      }
    }
    ++num_parts_;
  }
  unknown_.assign(static_cast<std::size_t>(n), -1);
  int rows = 0;
  for (int i = 0; i < n; ++i) {
    if (std::find(pinned_.begin(), pinned_.end(), i) == pinned_.end()) unknown_[static_cast<std::size_t>(i)] = rows++;
  }
  std::vector<Eigen::Triplet<double>> triplets;
  for (int i = 0; i < n; ++i) {
    const int ri = unknown_[static_cast<std::size_t>(i)];
    if (ri < 0) continue;
    double diagonal = 0;
    for (const auto& [j, c] : ring_[static_cast<std::size_t>(i)]) {
      diagonal += c;
      const int rj = unknown_[static_cast<std::size_t>(j)];
      if (rj >= 0) triplets.emplace_back(ri, rj, -c);
    }
    triplets.emplace_back(ri, ri, diagonal);
  }
  Eigen::SparseMatrix<double> A(rows, rows);
  A.setFromTriplets(triplets.begin(), triplets.end());
  solver_ = std::make_unique<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>>();
  if (rows > 0) {
    solver_->compute(A);
    if (solver_->info() != Eigen::Success) {
      throw GeometryError(source_ + ": ACAP Poisson system could not be factorised");
    }
  }
}

AcapEncoder::~AcapEncoder() = default;
AcapEncoder::AcapEncoder(AcapEncoder&&) noexcept = default;
AcapEncoder& AcapEncoder::operator=(AcapEncoder&&) noexcept = default;

void AcapEncoder::check_frame(const Eigen::MatrixXd& X, int width, const char* what) const {
  if (X.rows() != num_vertices() || X.cols() != width) {
    throw GeometryError(source_ + ": " + what + " is " + std::to_string(X.rows()) + "×" +
                        std::to_string(X.cols()) + ", the template has " +
                        std::to_string(num_vertices()) + " vertices (" + std::to_string(width) +
                        " columns expected)");
  }
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    if (!X.row(i).allFinite()) {
      throw GeometryError(source_ + ": " + what + " has a non-finite value at vertex " +
                          std::to_string(i));
    }
  }
}

Eigen::Matrix3d AcapEncoder::fit(int i, const Eigen::MatrixXd& deformed,
                                 const Eigen::MatrixXd& normals) const {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (const auto& [j, c] : ring_[static_cast<std::size_t>(i)]) {
    const Eigen::Vector3d e = (reference_.V.row(i) - reference_.V.row(j)).transpose();
    const Eigen::Vector3d d = (deformed.row(i) - deformed.row(j)).transpose();
    M += c * d * e.transpose();
  }
  M += prior_[static_cast<std::size_t>(i)] * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d normal_term =
      mean_weight_[static_cast<std::size_t>(i)] * normals.row(i).transpose() * normals_.row(i);
  const Eigen::Matrix3d& inverse = gram_inverse_[static_cast<std::size_t>(i)];
  const Eigen::Matrix3d T = (M + normal_term) * inverse;
  if (!flat_[static_cast<std::size_t>(i)]) return T;
  // A flat vertex's plane normals have no sign: take the one that keeps the orientation
  // (a motion's deformation gradient has a positive determinant).
  const Eigen::Matrix3d flipped = (M - normal_term) * inverse;
  return T.determinant() >= flipped.determinant() ? T : flipped;
}

std::vector<Eigen::Matrix3d> AcapEncoder::deformation_gradients(const Eigen::MatrixXd& deformed) const {
  check_frame(deformed, 3, "deformed mesh");
  const Eigen::MatrixXd normals = scaled_normals(reference_.F, deformed, ring_);
  std::vector<Eigen::Matrix3d> T(static_cast<std::size_t>(num_vertices()));
  for (int i = 0; i < num_vertices(); ++i) T[static_cast<std::size_t>(i)] = fit(i, deformed, normals);
  return T;
}

AcapEncoder::Polar AcapEncoder::polar_of(const Eigen::Matrix3d& T) {
  Polar p;
  Eigen::Matrix3d R;
  polar_decompose(T, R, p.S);
  const Eigen::AngleAxisd aa(R);
  p.r = aa.angle() * aa.axis();
  return p;
}

Eigen::RowVectorXd AcapEncoder::feature_of(const Polar& p, const Eigen::Vector3d& reference) {
  const Eigen::Vector3d r = nearest_rotation_vector(p.r, reference);
  const Eigen::Matrix3d& S = p.S;
  Eigen::RowVectorXd q(kAcapWidth);
  q << r.x(), r.y(), r.z(), S(0, 0), S(0, 1), S(0, 2), S(1, 1), S(1, 2), S(2, 2);
  return q;
}

Eigen::MatrixXd AcapEncoder::encode(const Eigen::MatrixXd& deformed) const {
  const std::vector<Eigen::Matrix3d> T = deformation_gradients(deformed);
  const int n = num_vertices();
  Eigen::MatrixXd Q(n, kAcapWidth);
  // Breadth-first from the vertex of least rotation in each part; each vertex takes the
  // representative nearest to the mean of its neighbours assigned before it.
  std::vector<Polar> polar;
  polar.reserve(T.size());
  for (const Eigen::Matrix3d& t : T) polar.push_back(polar_of(t));
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return polar[static_cast<std::size_t>(a)].r.norm() < polar[static_cast<std::size_t>(b)].r.norm();
  });
  std::vector<char> done(static_cast<std::size_t>(n), 0);
  for (int seed : order) {
    if (done[static_cast<std::size_t>(seed)]) continue;
    std::deque<int> queue{seed};
    done[static_cast<std::size_t>(seed)] = 1;
    while (!queue.empty()) {
      const int i = queue.front();
      queue.pop_front();
      Eigen::Vector3d reference = Eigen::Vector3d::Zero();
      int assigned = 0;
      for (const auto& [j, c] : ring_[static_cast<std::size_t>(i)]) {
        if (done[static_cast<std::size_t>(j)] == 2) {
          reference += Q.block<1, 3>(j, 0).transpose();
          ++assigned;
        }
      }
      if (assigned > 0) reference /= assigned;
      Q.row(i) = feature_of(polar[static_cast<std::size_t>(i)], reference);
      done[static_cast<std::size_t>(i)] = 2;
      for (const auto& [j, c] : ring_[static_cast<std::size_t>(i)]) {
        if (!done[static_cast<std::size_t>(j)]) {
          done[static_cast<std::size_t>(j)] = 1;
          queue.push_back(j);
        }
      }
    }
  }
  return Q;
}

std::vector<Eigen::MatrixXd> AcapEncoder::encode_sequence(
    const std::vector<Eigen::MatrixXd>& frames) const {
  std::vector<Eigen::MatrixXd> out;
  out.reserve(frames.size());
  Eigen::MatrixXd previous = Eigen::MatrixXd::Zero(num_vertices(), 3);
  for (const Eigen::MatrixXd& frame : frames) {
    const std::vector<Eigen::Matrix3d> T = deformation_gradients(frame);
    Eigen::MatrixXd Q(num_vertices(), kAcapWidth);
    for (int i = 0; i < num_vertices(); ++i) {
      Q.row(i) = feature_of(polar_of(T[static_cast<std::size_t>(i)]), previous.row(i).transpose());
    }
    previous = Q.leftCols(3);
    out.push_back(std::move(Q));
  }
  return out;
}

Eigen::MatrixXd AcapEncoder::decode(const Eigen::MatrixXd& features) const {
  return decode(features, reference_.V);
}

Eigen::MatrixXd AcapEncoder::decode(const Eigen::MatrixXd& features,
                                    const Eigen::MatrixXd& placement) const {
  check_frame(features, kAcapWidth, "feature matrix");
  check_frame(placement, 3, "placement");
  const int n = num_vertices();
  std::vector<Eigen::Matrix3d> T(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto q = features.row(i);
    Eigen::Matrix3d S;
    S << q(3), q(4), q(5), q(4), q(6), q(7), q(5), q(7), q(8);
    T[static_cast<std::size_t>(i)] = rotation_of(q.head<3>().transpose()) * S;
  }
  // b_i = ½ Σ_j c_ij (T_i + T_j)(q_i − q_j); pinned vertices sit at 0 of their part.
  const Eigen::Index rows = static_cast<Eigen::Index>(n - num_parts_);
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(rows, 3);
  for (int i = 0; i < n; ++i) {
    const int ri = unknown_[static_cast<std::size_t>(i)];
    if (ri < 0) continue;
    for (const auto& [j, c] : ring_[static_cast<std::size_t>(i)]) {
      const Eigen::Vector3d e = (reference_.V.row(i) - reference_.V.row(j)).transpose();
      b.row(ri) += (0.5 * c * (T[static_cast<std::size_t>(i)] + T[static_cast<std::size_t>(j)]) * e).transpose();
    }
  }
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n, 3);
  if (rows > 0) {
    const Eigen::MatrixXd x = solver_->solve(b);
    for (int i = 0; i < n; ++i) {
      if (unknown_[static_cast<std::size_t>(i)] >= 0) P.row(i) = x.row(unknown_[static_cast<std::size_t>(i)]);
    }
  }
  // Each part's centroid where `placement` has it.
  Eigen::MatrixXd shift = Eigen::MatrixXd::Zero(num_parts_, 3);
  Eigen::VectorXd count = Eigen::VectorXd::Zero(num_parts_);
  for (int i = 0; i < n; ++i) {
    const int p = part_[static_cast<std::size_t>(i)];
    shift.row(p) += placement.row(i) - P.row(i);
    count(p) += 1;
  }
  for (int i = 0; i < n; ++i) {
    const int p = part_[static_cast<std::size_t>(i)];
    P.row(i) += shift.row(p) / count(p);
  }
  return P;
}

FeatureScale FeatureScale::fit(const std::vector<Eigen::MatrixXd>& frames) {
  if (frames.empty()) throw Error("FeatureScale::fit: no frames");
  FeatureScale s;
  s.min = frames.front();
  s.max = frames.front();
  for (std::size_t f = 1; f < frames.size(); ++f) {
    if (frames[f].rows() != s.min.rows() || frames[f].cols() != s.min.cols()) {
      throw Error("FeatureScale::fit: frame " + std::to_string(f) + " is " +
                  std::to_string(frames[f].rows()) + "×" + std::to_string(frames[f].cols()) +
                  ", frame 0 is " + std::to_string(s.min.rows()) + "×" +
                  std::to_string(s.min.cols()));
    }
    s.min = s.min.cwiseMin(frames[f]);
    s.max = s.max.cwiseMax(frames[f]);
  }
  return s;
}

namespace {
void check_shape(const FeatureScale& s, const Eigen::MatrixXd& X, const char* what) {
  if (X.rows() != s.min.rows() || X.cols() != s.min.cols()) {
    throw Error(std::string("FeatureScale::") + what + ": features are " +
                std::to_string(X.rows()) + "×" + std::to_string(X.cols()) + ", fitted on " +
                std::to_string(s.min.rows()) + "×" + std::to_string(s.min.cols()));
  }
}
}  // namespace

Eigen::MatrixXd FeatureScale::normalise(const Eigen::MatrixXd& features) const {
  check_shape(*this, features, "normalise");
  const Eigen::ArrayXXd range = (max - min).array();
  const Eigen::ArrayXXd centred = features.array() - 0.5 * (max + min).array();
  return (range > 0).select(2 * kBound * centred / range.max(1e-300), 0.0).matrix();
}

Eigen::MatrixXd FeatureScale::denormalise(const Eigen::MatrixXd& normalised) const {
  check_shape(*this, normalised, "denormalise");
  return (normalised.array() * (max - min).array() / (2 * kBound) + 0.5 * (max + min).array())
      .matrix();
}

}  // namespace skinlab::geometry

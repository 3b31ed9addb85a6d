#include "framework/geometry/delta_mush.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "framework/geometry/one_ring.hpp"
#include "framework/geometry/vertex_normals.hpp"

namespace skinlab::geometry {

namespace {

/// A tangent shorter than this fraction of its edge is parallel to the normal: no frame.
constexpr double kMinTangentFraction = 1e-6;

/// The frame [t b n] at vertex i of the smoothed mesh S with normals N, tangent towards
/// neighbour j; false when it is unusable.
bool frame_at(const Eigen::MatrixXd& S, const Eigen::MatrixXd& N, int i, int j,
              Eigen::Matrix3d& frame) {
  const Eigen::Vector3d n = N.row(i).transpose();
  if (n.squaredNorm() == 0) return false;  // vertex_normals: on no face, or normals cancel
  const Eigen::Vector3d edge = (S.row(j) - S.row(i)).transpose();
  const Eigen::Vector3d t = edge - edge.dot(n) * n;
  const double length = t.norm();
  if (!(length > kMinTangentFraction * edge.norm())) return false;
  frame.col(0) = t / length;
  frame.col(1) = n.cross(frame.col(0));
  frame.col(2) = n;
  return true;
}

}  // namespace

DeltaMush::DeltaMush(const Mesh& rest, const DeltaMushOptions& options, const std::string& source)
    : options_(options), source_(source), faces_(rest.F) {
  rest.validate(source);
  if (options.iterations < 1) {
    throw GeometryError(source + ": delta mush needs iterations >= 1, got " +
                        std::to_string(options.iterations));
  }
  if (!(options.step > 0 && options.step <= 1)) {
    throw GeometryError(source + ": delta mush step must be in (0, 1], got " +
                        std::to_string(options.step));
  }
  neighbours_ = one_ring(rest).neighbours;

  const Eigen::MatrixXd S = smooth(rest.V);
  const Eigen::MatrixXd N = vertex_normals(Mesh{S, faces_});
  const int n = rest.num_vertices();
  tangent_neighbour_.assign(static_cast<std::size_t>(n), -1);
  detail_ = Eigen::MatrixXd::Zero(n, 3);
  for (int i = 0; i < n; ++i) {
    // The neighbour whose edge has the longest projection onto the tangent plane.
    const Eigen::Vector3d normal = N.row(i).transpose();
    double longest = 0;
    for (int j : neighbours_[static_cast<std::size_t>(i)]) {
      const Eigen::Vector3d edge = (S.row(j) - S.row(i)).transpose();
      const double projected = (edge - edge.dot(normal) * normal).norm();
      if (projected > longest) {
        longest = projected;
        tangent_neighbour_[static_cast<std::size_t>(i)] = j;
      }
    }
    Eigen::Matrix3d frame;
    const int j = tangent_neighbour_[static_cast<std::size_t>(i)];
    if (j < 0 || !frame_at(S, N, i, j, frame)) {
      tangent_neighbour_[static_cast<std::size_t>(i)] = -1;
      ++rest_passthrough_;
      continue;
    }
    detail_.row(i) = (frame.transpose() * (rest.V.row(i) - S.row(i)).transpose()).transpose();
  }
}

Eigen::MatrixXd DeltaMush::smooth(const Eigen::MatrixXd& X) const {
  Eigen::MatrixXd current = X, next(X.rows(), 3);
  const double keep = 1 - options_.step;
  for (int k = 0; k < options_.iterations; ++k) {
    for (Eigen::Index i = 0; i < current.rows(); ++i) {
      const auto& ring = neighbours_[static_cast<std::size_t>(i)];
      if (ring.empty()) {
        next.row(i) = current.row(i);
        continue;
      }
      Eigen::RowVector3d mean = Eigen::RowVector3d::Zero();
      for (int j : ring) mean += current.row(j);
      mean /= static_cast<double>(ring.size());
      next.row(i) = keep * current.row(i) + options_.step * mean;
    }
    current.swap(next);
  }
  return current;
}

Eigen::MatrixXd DeltaMush::deform(const Eigen::MatrixXd& posed, int* passthrough) const {
  if (posed.rows() != detail_.rows() || posed.cols() != 3) {
    throw GeometryError(source_ + ": delta mush: the posed mesh is " +
                        std::to_string(posed.rows()) + "x" + std::to_string(posed.cols()) +
                        ", the rest mesh has " + std::to_string(detail_.rows()) + " vertices (" +
                        std::to_string(detail_.rows()) + "x3 expected)");
  }
  for (Eigen::Index i = 0; i < posed.rows(); ++i) {
    if (!posed.row(i).allFinite()) {
      throw GeometryError(source_ + ": delta mush: posed vertex " + std::to_string(i) +
                          " has a non-finite coordinate");
    }
  }
  const Eigen::MatrixXd S = smooth(posed);
  const Eigen::MatrixXd N = vertex_normals(Mesh{S, faces_});
  Eigen::MatrixXd out = posed;
  int kept = 0;
  for (Eigen::Index i = 0; i < posed.rows(); ++i) {
    const int j = tangent_neighbour_[static_cast<std::size_t>(i)];
    Eigen::Matrix3d frame;
    if (j < 0 || !frame_at(S, N, static_cast<int>(i), j, frame)) {
      ++kept;
      continue;
    }
    out.row(i) = S.row(i) + (frame * detail_.row(i).transpose()).transpose();
  }
  if (passthrough) *passthrough = kept;
  return out;
}

}  // namespace skinlab::geometry

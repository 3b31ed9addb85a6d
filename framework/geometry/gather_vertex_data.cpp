#include "framework/geometry/gather_vertex_data.hpp"

#include <string>
#include <vector>

namespace skinlab::geometry {
namespace {

void check_map(Eigen::Index num_new, const Eigen::VectorXi& old_to_new) {
  for (Eigen::Index i = 0; i < old_to_new.size(); ++i) {
    if (old_to_new(i) < 0 || old_to_new(i) >= num_new) {
      throw GeometryError("gather_vertex_data: original vertex " + std::to_string(i) +
                          " maps to " + std::to_string(old_to_new(i)) + ", but the data has " +
                          std::to_string(num_new) + " rows");
    }
  }
}

}  // namespace

Eigen::MatrixXd gather_vertex_data(const Eigen::MatrixXd& data, const Eigen::VectorXi& old_to_new) {
  check_map(data.rows(), old_to_new);
  Eigen::MatrixXd out(old_to_new.size(), data.cols());
  for (Eigen::Index i = 0; i < old_to_new.size(); ++i) out.row(i) = data.row(old_to_new(i));
  return out;
}

SparseWeights gather_vertex_data(const SparseWeights& data, const Eigen::VectorXi& old_to_new) {
  check_map(data.rows(), old_to_new);
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index i = 0; i < old_to_new.size(); ++i) {
    for (SparseWeights::InnerIterator it(data, old_to_new(i)); it; ++it) {
      entries.emplace_back(static_cast<int>(i), static_cast<int>(it.col()), it.value());
    }
  }
  SparseWeights out(old_to_new.size(), data.cols());
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

}  // namespace skinlab::geometry

#include "framework/geometry/average_vertex_data.hpp"

#include <string>
#include <vector>

namespace skinlab::geometry {
namespace {

// Number of original vertices behind every new vertex; throws on a bad map or an orphan.
std::vector<int> group_sizes(Eigen::Index data_rows, const Eigen::VectorXi& old_to_new,
                             int num_new) {
  if (data_rows != old_to_new.size()) {
    throw GeometryError("average_vertex_data: data has " + std::to_string(data_rows) +
                        " rows but the map has " + std::to_string(old_to_new.size()) +
                        " original vertices");
  }
  if (num_new < 0) throw GeometryError("average_vertex_data: negative vertex count");
  std::vector<int> count(static_cast<size_t>(num_new), 0);
  for (Eigen::Index i = 0; i < old_to_new.size(); ++i) {
    if (old_to_new(i) < 0 || old_to_new(i) >= num_new) {
      throw GeometryError("average_vertex_data: original vertex " + std::to_string(i) +
                          " maps to " + std::to_string(old_to_new(i)) + ", outside [0, " +
                          std::to_string(num_new) + ")");
    }
    ++count[static_cast<size_t>(old_to_new(i))];
  }
  for (int n = 0; n < num_new; ++n) {
    if (count[static_cast<size_t>(n)] == 0) {
      throw GeometryError("average_vertex_data: new vertex " + std::to_string(n) +
                          " has no original vertex");
    }
  }
  return count;
}

}  // namespace

Eigen::MatrixXd average_vertex_data(const Eigen::MatrixXd& data, const Eigen::VectorXi& old_to_new,
                                    int num_new) {
  const std::vector<int> count = group_sizes(data.rows(), old_to_new, num_new);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(num_new, data.cols());
  for (Eigen::Index i = 0; i < old_to_new.size(); ++i) out.row(old_to_new(i)) += data.row(i);
  for (int n = 0; n < num_new; ++n) out.row(n) /= count[static_cast<size_t>(n)];
  return out;
}

SparseWeights average_vertex_data(const SparseWeights& data, const Eigen::VectorXi& old_to_new,
                                  int num_new) {
  const std::vector<int> count = group_sizes(data.rows(), old_to_new, num_new);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(data.nonZeros()));
  for (Eigen::Index i = 0; i < data.outerSize(); ++i) {
    const int n = old_to_new(i);
    for (SparseWeights::InnerIterator it(data, i); it; ++it) {
      entries.emplace_back(n, static_cast<int>(it.col()), it.value() / count[static_cast<size_t>(n)]);
    }
  }
  SparseWeights out(num_new, data.cols());
  out.setFromTriplets(entries.begin(), entries.end());  // sums the rows of a merged group
  return out;
}

}  // namespace skinlab::geometry

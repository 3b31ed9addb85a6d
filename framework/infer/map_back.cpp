#include "framework/infer/map_back.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <set>
#include <string>

#include "framework/core/error.hpp"

namespace skinlab::infer {

namespace {

/// The float's shortest decimal form as a double (0.3f → 0.3, not 0.30000001192092896), so the
/// rig text is as short as the prediction's precision warrants.
double shortest(float value) { return std::strtod(fmt::format("{}", value).c_str(), nullptr); }

}  // namespace

void prune_rows(data::RowMatrixXd& W, double fraction) {
  if (!(fraction >= 0 && fraction <= 1)) {
    throw Error(fmt::format("prune_rows: fraction must be in [0, 1], got {}", fraction));
  }
  if (fraction == 0) return;
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    auto row = W.row(v);
    const double cut = fraction * row.maxCoeff();
    row = (row.array() < cut).select(0.0, row);
    const double sum = row.sum();
    if (sum > 0) row /= sum;
  }
}

data::RowMatrixXf to_source_vertices(const data::RowMatrixXf& W, const std::vector<int>& vertex_map) {
  data::RowMatrixXf out(static_cast<Eigen::Index>(vertex_map.size()), W.cols());
  for (std::size_t i = 0; i < vertex_map.size(); ++i) {
    const int v = vertex_map[i];
    if (v < 0 || v >= W.rows()) {
      throw Error(fmt::format("vertex map: source vertex {} maps to {}, outside [0, {})", i, v,
                              W.rows()));
    }
    out.row(static_cast<Eigen::Index>(i)) = W.row(v);
  }
  return out;
}

geometry::SparseWeights joint_weights_of(const data::RowMatrixXf& W, const data::RowMatrixXi& bones,
                                         int num_joints) {
  if (bones.rows() != W.cols()) {
    throw Error(fmt::format("joint weights: {} bone columns but {} bones", W.cols(), bones.rows()));
  }
  std::vector<Eigen::Triplet<double>> triplets;
  std::vector<float> row(static_cast<std::size_t>(num_joints));
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    std::fill(row.begin(), row.end(), 0.0f);
    for (Eigen::Index b = 0; b < W.cols(); ++b) row[static_cast<std::size_t>(bones(b, 0))] += W(v, b);
    for (int j = 0; j < num_joints; ++j) {
      if (row[static_cast<std::size_t>(j)] != 0.0f) {
        triplets.emplace_back(static_cast<int>(v), j, shortest(row[static_cast<std::size_t>(j)]));
      }
    }
  }
  geometry::SparseWeights out(W.rows(), num_joints);
  out.setFromTriplets(triplets.begin(), triplets.end());
  out.makeCompressed();
  return out;
}

geometry::Skeleton source_skeleton(const data::PreparedCharacter& character) {
  geometry::Skeleton s;
  s.parents = character.parents;
  const Eigen::Matrix4d back = character.normalisation.inverse();
  s.positions.resize(character.joints.rows(), 3);
  for (Eigen::Index j = 0; j < character.joints.rows(); ++j) {
    const Eigen::Vector4d p(character.joints(j, 0), character.joints(j, 1), character.joints(j, 2), 1);
    s.positions.row(j) = (back * p).head<3>().transpose();
  }
  s.names = rig_joint_names(character.joint_names);
  return s;
}

std::vector<std::string> rig_joint_names(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  std::set<std::string> used;
  for (const auto& original : names) {
    std::string name = original.empty() ? "joint" : original;
    for (char& ch : name) {
      if (ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n' || ch == '#') ch = '_';
    }
    std::string unique = name;
    for (int n = 2; used.count(unique); ++n) unique = name + "_" + std::to_string(n);
    used.insert(unique);
    out.push_back(unique);
  }
  return out;
}

}  // namespace skinlab::infer

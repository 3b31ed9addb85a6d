#include "framework/eval/deformation_error.hpp"

#include <cmath>
#include <random>

#include "framework/core/registry.hpp"
#include "framework/core/stable_random.hpp"
#include "framework/eval/value_display.hpp"
#include "framework/eval/weights.hpp"
#include "framework/geometry/lbs.hpp"

namespace skinlab::eval {

DeformationError::Options DeformationError::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "metric 'deformation_error'");
  f.optional("poses", o.poses).check(o.poses >= 1, "poses", "must be at least 1");
  f.optional("fraction", o.fraction)
      .check(o.fraction >= 0 && o.fraction <= 1, "fraction", "must be in [0, 1]");
  f.optional("sigma_degrees", o.sigma_degrees)
      .check(o.sigma_degrees > 0 && o.sigma_degrees <= 180, "sigma_degrees",
             "must be in (0, 180] (degrees)");
  f.optional("seed", o.seed);
  f.optional("prune", o.prune).check(o.prune >= 0 && o.prune <= 1, "prune", "must be in [0, 1]");
  f.finish();
  return o;
}

namespace {

geometry::Skeleton skeleton_of(const data::PreparedCharacter& c) {
  geometry::Skeleton s;
  s.names = c.joint_names;
  s.positions = c.joints;
  s.parents = c.parents;
  return s;
}

}  // namespace

std::vector<std::vector<Eigen::Matrix3d>> DeformationError::poses(
    const data::PreparedCharacter& character) const {
  std::mt19937 rng = keyed_engine(options_.seed, character.name);
  const geometry::Skeleton skeleton = skeleton_of(character);
  std::vector<std::vector<Eigen::Matrix3d>> out;
  for (int p = 0; p < options_.poses; ++p) {
    out.push_back(geometry::random_pose(skeleton, rng, options_.fraction, options_.sigma_degrees));
  }
  return out;
}

Eigen::MatrixXd DeformationError::vertex_distances(const MetricInputs& in) const {
  TORCH_CHECK(in.character != nullptr, error_context(in, "deformation_error"),
              ": needs the prepared character (MetricInputs::character) to pose its mesh");
  auto [P, G] = read_weights(in, "deformation_error");
  prune_rows(P, options_.prune);
  const data::PreparedCharacter& c = *in.character;
  const std::string context = error_context(in, "deformation_error");
  TORCH_CHECK(c.joints.rows() == c.num_joints() && c.joints.cols() == 3 &&
                  static_cast<int>(c.parents.size()) == c.num_joints(),
              context, ": the skeleton has ", c.num_joints(), " joint names, ", c.joints.rows(),
              "×", c.joints.cols(), " joint positions and ", c.parents.size(), " parents");
  const geometry::SparseWeights Wp = joint_weights(P, c.bones, c.num_joints());
  const geometry::SparseWeights Wg = joint_weights(G, c.bones, c.num_joints());
  const geometry::Skeleton skeleton = skeleton_of(c);
  const Eigen::MatrixXd V = c.V;
  const auto all_poses = poses(c);
  Eigen::MatrixXd D(all_poses.size(), V.rows());
  for (std::size_t p = 0; p < all_poses.size(); ++p) {
    const auto T = geometry::forward_kinematics(skeleton, all_poses[p]);
    D.row(static_cast<Eigen::Index>(p)) =
        (geometry::lbs(V, Wp, T) - geometry::lbs(V, Wg, T)).rowwise().norm().transpose();
  }
  return D;
}

std::map<std::string, double> DeformationError::operator()(const MetricInputs& in) const {
  const Eigen::MatrixXd D = vertex_distances(in);
  if (D.size() == 0) return {{"deformation_error", 0.0}, {"deformation_error_max", 0.0}};
  return {{"deformation_error", D.mean()}, {"deformation_error_max", D.maxCoeff()}};
}

}  // namespace skinlab::eval

SKINLAB_DECLARE_VALUE({"deformation_error", "Dist. err.", "", false, false, 6});
SKINLAB_DECLARE_VALUE({"deformation_error_max", "Max dist. err.", "", false, false, 4});
SKINLAB_REGISTER(metric, deformation_error, skinlab::eval::DeformationError);

#pragma once
/// \file
/// `deformation_error`: how differently the mesh deforms under the predicted and the artist
/// weights (HeterSkinNet Sec. 4.3, "Distance error"; RigNet's "avg dist." and "max dist.").
/// Outputs, in metres of the normalised frame (the character is 1 m tall):
///
///     deformation_error     = mean over poses p and vertices v of ‖x_p,v(P) − x_p,v(G)‖
///     deformation_error_max = max  over poses p and vertices v of the same distance
///
/// where x_p,v(W) is vertex v posed by linear blend skinning (geometry/lbs.hpp) with bone
/// weights W mapped to joints (a bone moves with its start joint, weights.hpp joint_weights),
/// and P is the pruned prediction (weights.hpp prune_rows, default `prune` = 0.25, as
/// precision_recall and avg_l1 use it). The evaluator averages both over characters.
///
/// Poses (Sec. 4.3: 10 poses, 30% of the bones rotated by angles from N(0, 25°)): `poses`
/// (default 10) poses from geometry::random_pose, each rotating round(`fraction` · #J) joints
/// (default 0.3) about uniformly random axes by angles from N(0, `sigma_degrees`²) (default 25)
/// about their rest positions (forward_kinematics). The random stream is a function of `seed`
/// (default 0) and the character's name only, through a fixed hash (FNV-1a, not std::hash) and
/// std::seed_seq into mt19937, with no std:: distribution involved: every method, run and
/// machine evaluates a character on the same poses. The run's training seed is deliberately not
/// used. The poses do not depend on the weights.

#include <Eigen/Core>
#include <cstdint>

#include "framework/core/config.hpp"
#include "framework/core/stable_random.hpp"
#include "framework/eval/metric.hpp"

namespace skinlab::eval {

class DeformationError final : public Metric {
 public:
  struct Options {
    int poses = 10;               ///< random poses per character, ≥ 1
    double fraction = 0.3;        ///< fraction of the joints rotated in each pose, [0, 1]
    double sigma_degrees = 25.0;  ///< standard deviation of the rotation angles, (0, 180]
    std::int64_t seed = 0;        ///< pose seed, combined with the character's name
    double prune = 0.25;          ///< fraction of the row maximum below which P is zeroed; [0, 1]
    static Options from(const config::Node& node);
  };
  explicit DeformationError(Options options) : options_(options) {}
  std::map<std::string, double> operator()(const MetricInputs& in) const override;
  std::vector<std::string> names() const override {
    return {"deformation_error", "deformation_error_max"};
  }

  /// The evaluation poses of `character`: `poses` lists of #J local joint rotations (for
  /// forward_kinematics), a function of the options, the name and #J only.
  std::vector<std::vector<Eigen::Matrix3d>> poses(const data::PreparedCharacter& character) const;

  /// #poses×#V distances ‖x_p,v(P) − x_p,v(G)‖ in metres, for per-vertex error maps (Fig. 8).
  /// Needs `in.character`; throws c10::Error as weights.hpp read_weights does, and when the
  /// character is missing.
  Eigen::MatrixXd vertex_distances(const MetricInputs& in) const;

  const Options& options() const { return options_; }

 private:
  Options options_;
};

/// 64-bit FNV-1a hash (core/stable_random.hpp), also reachable here where the poses use it.
using skinlab::stable_hash;

}  // namespace skinlab::eval

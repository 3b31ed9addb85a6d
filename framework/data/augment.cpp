#include "framework/data/augment.hpp"

#include <cmath>

#include "framework/core/error.hpp"
#include "framework/core/stable_random.hpp"
#include "framework/geometry/lbs.hpp"

namespace skinlab::data {

AugmentOptions AugmentOptions::from(const config::Node& node) {
  AugmentOptions o;
  config::Fields f(node, "preprocess.augment", {});
  f.optional("copies", o.copies);
  f.check(o.copies >= 0, "copies", "must be ≥ 0 (0: no augmented copies)");
  f.optional("seed", o.seed);

  const config::Node pose = f.section("pose");
  if (pose.exists() && !pose.is_null()) {
    config::Fields p(pose, "preprocess.augment.pose", {});
    o.pose = true;
    p.optional("clips", o.pose_clips);
    p.optional("random_degrees", o.random_degrees);
    p.check(!pose.has("random_degrees") || (o.random_degrees >= 0 && o.random_degrees <= 180),
            "random_degrees", "must be in [0, 180] (the standard deviation of the angles)");
    p.optional("random_fraction", o.random_fraction);
    p.check(o.random_fraction >= 0 && o.random_fraction <= 1, "random_fraction",
            "must be in [0, 1] (the share of the joints turned)");
    p.finish();
    if (!o.pose_clips && !pose.has("random_degrees")) {
      pose.fail("poses nothing: needs 'clips: true', 'random_degrees', or both");
    }
  }

  const config::Node scale = f.section("scale");
  if (scale.exists() && !scale.is_null()) {
    const auto range = scale.as<std::vector<double>>();
    f.check(range.size() == 2, "scale", "must be [min, max] (factors per axis)");
    o.scale = true;
    o.scale_min = range[0];
    o.scale_max = range[1];
    f.check(std::isfinite(o.scale_min) && std::isfinite(o.scale_max) && o.scale_min > 0, "scale",
            "factors must be finite and positive");
    f.check(o.scale_min <= o.scale_max, "scale", "must be [min, max] with min ≤ max");
  }

  f.optional("mirror", o.mirror);
  f.check(o.mirror >= 0 && o.mirror <= 1, "mirror", "must be a probability in [0, 1]");
  f.finish();
  f.check(o.copies == 0 || o.pose || o.scale || o.mirror > 0, "copies",
          "asks for copies but no kind of augmentation is on (pose, scale or mirror): they "
          "would equal their originals");
  return o;
}

std::string augmented_name(const std::string& name, int copy) {
  return name + "~aug" + std::to_string(copy);
}

namespace {
// Nested so that these names never meet another file's in a unity translation unit.
namespace augment_detail {

bool usable(const datasets::Animation& clip, int joints) {
  if (clip.frames.empty() || static_cast<int>(clip.bind.size()) != joints) return false;
  for (const auto& frame : clip.frames) {
    if (static_cast<int>(frame.size()) != joints) return false;
  }
  return true;
}

/// Index in [0, n) from one uniform draw.
std::size_t pick(std::mt19937& rng, std::size_t n) {
  return std::min(n - 1, static_cast<std::size_t>(uniform_open(rng) * static_cast<double>(n)));
}

bool is_identity(const std::vector<Eigen::Affine3d>& pose) {
  for (const auto& t : pose) {
    if (t.matrix() != Eigen::Matrix4d::Identity()) return false;
  }
  return true;
}

Eigen::MatrixXd transform_rows(const Eigen::MatrixXd& P, const Eigen::Matrix3d& A) {
  return P * A.transpose();
}

}  // namespace augment_detail
}  // namespace

Augmentation draw_augmentation(const AugmentOptions& options, const std::string& name, int copy,
                               const geometry::Skeleton& skeleton,
                               const std::vector<datasets::Animation>& clips,
                               const Eigen::Matrix4d& to_frame) {
  using namespace augment_detail;
  Augmentation a;
  const std::string key = augmented_name(name, copy);
  const int joints = skeleton.num_joints();
  if (options.pose) {
    std::mt19937 rng = keyed_engine(options.seed, key + "/pose");
    std::vector<const datasets::Animation*> usable_clips;
    if (options.pose_clips) {
      for (const auto& clip : clips) {
        if (usable(clip, joints)) usable_clips.push_back(&clip);
      }
    }
    if (!usable_clips.empty()) {
      const std::size_t c = pick(rng, usable_clips.size());
      const datasets::Animation& clip = *usable_clips[c];
      const std::size_t f = pick(rng, clip.frames.size());
      // Conjugated into the normalised frame, as the stored clips are (preprocess.cpp).
      const Eigen::Affine3d S(to_frame);
      const Eigen::Affine3d S_inv = S.inverse();
      for (int j = 0; j < joints; ++j) {
        const auto& t = clip.frames[f][static_cast<std::size_t>(j)];
        const auto& b = clip.bind[static_cast<std::size_t>(j)];
        a.pose.push_back(S * Eigen::Affine3d((t * b.inverse()).matrix()) * S_inv);
      }
      a.pose_source = "clip '" + clip.name + "' frame " + std::to_string(f);
    } else if (options.random_degrees >= 0) {
      a.pose = geometry::forward_kinematics(
          skeleton,
          geometry::random_pose(skeleton, rng, options.random_fraction, options.random_degrees));
      a.pose_source = "random";
    }
  }
  if (options.scale) {
    std::mt19937 rng = keyed_engine(options.seed, key + "/scale");
    const double lo = std::log(options.scale_min), hi = std::log(options.scale_max);
    for (int axis = 0; axis < 3; ++axis) {
      a.scale(axis) = std::exp(lo + uniform_open(rng) * (hi - lo));
    }
  }
  if (options.mirror > 0) {
    std::mt19937 rng = keyed_engine(options.seed, key + "/mirror");
    a.mirror = uniform_open(rng) < options.mirror;
  }
  return a;
}

void apply_augmentation(const Augmentation& augmentation, const geometry::SparseWeights& weights,
                        geometry::Mesh& mesh, geometry::Skeleton& skeleton) {
  using namespace augment_detail;
  const auto& T = augmentation.pose;
  if (!T.empty() && !is_identity(T)) {
    mesh.V = geometry::lbs(mesh.V, weights, T);
    const bool tips = skeleton.leaf_tips.rows() == skeleton.num_joints();
    for (int j = 0; j < skeleton.num_joints(); ++j) {
      const auto& t = T[static_cast<std::size_t>(j)];
      skeleton.positions.row(j) = (t * Eigen::Vector3d(skeleton.positions.row(j))).transpose();
      if (tips) {
        skeleton.leaf_tips.row(j) = (t * Eigen::Vector3d(skeleton.leaf_tips.row(j))).transpose();
      }
    }
  }
  Eigen::Vector3d diagonal = augmentation.scale;
  if (augmentation.mirror) diagonal.x() = -diagonal.x();
  if (diagonal != Eigen::Vector3d::Ones()) {
    const Eigen::Matrix3d A = diagonal.asDiagonal();
    mesh.V = transform_rows(mesh.V, A);
    skeleton.positions = transform_rows(skeleton.positions, A);
    if (skeleton.leaf_tips.size() > 0) skeleton.leaf_tips = transform_rows(skeleton.leaf_tips, A);
  }
  if (augmentation.mirror) mesh.F.col(1).swap(mesh.F.col(2));
}

geometry::Similarity augment(const Augmentation& augmentation,
                             const geometry::SparseWeights& weights, geometry::Mesh& mesh,
                             geometry::Skeleton& skeleton, const std::string& name) {
  const bool moves =
      (!augmentation.pose.empty() && !augment_detail::is_identity(augmentation.pose)) ||
      augmentation.scale != Eigen::Vector3d::Ones() || augmentation.mirror;
  if (!moves) return {};
  apply_augmentation(augmentation, weights, mesh, skeleton);
  geometry::Character c;
  c.name = name;
  c.mesh = std::move(mesh);
  c.skeleton = std::move(skeleton);
  const geometry::Similarity s = geometry::normalize(c);
  mesh = std::move(c.mesh);
  skeleton = std::move(c.skeleton);
  if (skeleton.leaf_tips.size() > 0) skeleton.leaf_tips = s.apply(skeleton.leaf_tips);
  return s;
}

}  // namespace skinlab::data

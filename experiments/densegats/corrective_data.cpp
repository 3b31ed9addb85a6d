#include "experiments/densegats/corrective_data.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>

#include "framework/core/error.hpp"
#include "framework/tensors/tensors.hpp"
#include "framework/geometry/lbs.hpp"
#include "framework/geometry/orient_outward.hpp"
#include "framework/geometry/vertex_normals.hpp"

namespace skinlab::densegats {

namespace {

/// N⁻¹ · T · N for a similarity N (undoes the normalisation) as a rigid transform.
Eigen::Isometry3d conjugate(const Eigen::Matrix4d& N, const Eigen::Matrix4d& N_inverse,
                            const Eigen::Isometry3d& T) {
  const Eigen::Matrix4d m = N_inverse * T.matrix() * N;
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = Eigen::Quaterniond(Eigen::Matrix3d(m.topLeftCorner<3, 3>())).normalized().toRotationMatrix();
  out.translation() = m.topRightCorner<3, 1>();
  return out;
}

}  // namespace

CorrectiveOptions CorrectiveOptions::from(const config::Node& node) {
  CorrectiveOptions o;
  config::Fields f(node, "corrective", {});
  f.optional("skeleton", o.skeleton);
  f.optional("frame_stride", o.frame_stride);
  f.optional("max_poses_per_character", o.max_poses_per_character);
  f.optional("height_m", o.height_m);
  const config::Node mush = f.section("delta_mush");
  if (mush.exists() && !mush.is_null()) {
    config::Fields m(mush, "corrective.delta_mush", {});
    m.optional("iterations", o.delta_mush.iterations);
    m.optional("step", o.delta_mush.step);
    m.check(o.delta_mush.iterations >= 1, "iterations", "must be ≥ 1");
    m.check(o.delta_mush.step > 0 && o.delta_mush.step <= 1, "step", "must be in (0, 1]");
    m.finish();
  }
  f.optional("samples_per_epoch", o.samples_per_epoch)
      .check(o.samples_per_epoch >= 1, "samples_per_epoch", "must be ≥ 1");
  f.optional("batch_size", o.batch_size).check(o.batch_size >= 1, "batch_size", "must be ≥ 1");
  f.optional("window", o.window).check(o.window >= 0, "window", "must be ≥ 0 (0: whole mesh)");
  f.optional("eval_poses", o.eval_poses).check(o.eval_poses >= 1, "eval_poses", "must be ≥ 1");
  const config::Node plateau = f.section("plateau");
  if (plateau.exists() && !plateau.is_null()) {
    config::Fields p(plateau, "corrective.plateau", {});
    p.optional("factor", o.plateau_factor)
        .check(o.plateau_factor > 0 && o.plateau_factor <= 1, "factor", "must be in (0, 1]");
    p.optional("patience", o.plateau_patience)
        .check(o.plateau_patience >= 1, "patience", "must be ≥ 1");
    p.optional("min_lr", o.plateau_min_lr).check(o.plateau_min_lr >= 0, "min_lr", "must be ≥ 0");
    p.finish();
  }
  f.optional("baseline", o.baseline)
      .check(o.baseline.empty() || o.baseline == "lbs" || o.baseline == "dqs", "baseline",
             "must be lbs or dqs (or absent: a trained model)");
  f.check(!o.skeleton.empty(), "skeleton", "must name a skeleton family");
  f.check(o.frame_stride >= 1, "frame_stride", "must be ≥ 1");
  f.check(o.max_poses_per_character >= 0, "max_poses_per_character", "must be ≥ 0 (0: all)");
  f.check(o.height_m > 0, "height_m", "must be positive");
  f.finish();
  return o;
}

CorrectiveData::CorrectiveData(const data::Dataset& dataset, const std::string& file,
                               const CorrectiveOptions& options)
    : options_(options), file_(file) {
  // The family, its joint layout, and the pooled clips (one per name, in file order).
  const data::PreparedCharacter* first = nullptr;
  std::map<std::string, int> clip_index;
  for (std::size_t i = 0; i < dataset.characters.size(); ++i) {
    const data::PreparedCharacter& c = dataset.characters[i];
    if (c.skeleton != options.skeleton) continue;
    if (first == nullptr) {
      first = &c;
      num_joints_ = c.num_joints();
    } else if (c.joint_names != first->joint_names) {
      throw IoError(fmt::format("{}: characters '{}' and '{}' of skeleton family '{}' have "
                                "different joints ({} and {}); the corrective task needs one "
                                "shared skeleton",
                                file, first->name, c.name, options.skeleton, first->num_joints(),
                                c.num_joints()));
    }
    const Eigen::Matrix4d N = c.normalisation, N_inverse = c.normalisation.inverse();
    for (const data::AnimationData& a : c.animations) {
      if (clip_index.count(a.name)) continue;
      if (a.frames.size() != static_cast<std::size_t>(a.num_frames) * num_joints_ * 12) {
        throw IoError(fmt::format("{}: clip '{}' of character '{}' does not have {} joints",
                                  file, a.name, c.name, num_joints_));
      }
      PooledClip clip{a.name, c.name, {}};
      for (int f = 0; f < a.num_frames; ++f) {
        std::vector<Eigen::Isometry3d> frame;
        frame.reserve(static_cast<std::size_t>(num_joints_));
        for (int j = 0; j < num_joints_; ++j) {
          const float* m = a.frames.data() + (static_cast<std::size_t>(f) * num_joints_ + j) * 12;
          frame.push_back(conjugate(N, N_inverse, data::joint_transform(m)));
        }
        clip.frames.push_back(std::move(frame));
      }
      clip_index[a.name] = static_cast<int>(clips_.size());
      clips_.push_back(std::move(clip));
    }
  }
  if (first == nullptr) {
    throw IoError(fmt::format("{}: no character of skeleton family '{}' (corrective.skeleton)",
                              file, options.skeleton));
  }

  // The pose list every character shares.
  std::vector<PoseRef> poses;
  for (std::size_t k = 0; k < clips_.size(); ++k) {
    for (std::size_t f = 0; f < clips_[k].frames.size();
         f += static_cast<std::size_t>(options.frame_stride)) {
      poses.push_back({static_cast<int>(k), static_cast<int>(f)});
    }
  }
  if (options.max_poses_per_character > 0 &&
      poses.size() > static_cast<std::size_t>(options.max_poses_per_character)) {
    std::vector<PoseRef> kept;
    const std::size_t n = static_cast<std::size_t>(options.max_poses_per_character);
    for (std::size_t k = 0; k < n; ++k) kept.push_back(poses[k * poses.size() / n]);
    poses = std::move(kept);
  }

  for (std::size_t i = 0; i < dataset.characters.size(); ++i) {
    const data::PreparedCharacter& c = dataset.characters[i];
    if (c.skeleton != options.skeleton) continue;
    const std::vector<float>* bind = c.bind_pose();
    if (bind == nullptr) {
      excluded_.push_back(c.name + ": no bind pose in the file (neither its own nor a clip's; a "
                          "file written before bind poses were stored: re-run `skinlab prepare`)");
      spdlog::info("corrective: left out {}", excluded_.back());
      continue;
    }
    CorrectiveCharacter out;
    out.name = c.name;
    out.dataset_index = static_cast<int>(i);
    geometry::Mesh mesh{c.V, c.F};
    out.mesh = geometry::orient_outward(mesh);
    out.weights = c.weights;
    out.joints = c.joints;
    out.normalisation = c.normalisation;
    out.root = static_cast<int>(std::find(c.parents.begin(), c.parents.end(), -1) - c.parents.begin());
    for (int j = 0; j < num_joints_; ++j) {
      out.bind_inverse.push_back(data::joint_transform(bind->data() + static_cast<std::size_t>(j) * 12).inverse());
    }
    out.mush = std::make_shared<const geometry::DeltaMush>(out.mesh, options.delta_mush, c.name);
    out.one_ring = data::to_long(c.one_ring_edges);
    out.poses = poses;
    characters_.push_back(std::move(out));
  }
  if (characters_.empty()) {
    throw IoError(fmt::format("{}: no character of skeleton family '{}' has a bind pose in the "
                              "file (re-run `skinlab prepare` with this build)",
                              file, options.skeleton));
  }
  if (clips_.empty()) {
    throw IoError(fmt::format("{}: no character of skeleton family '{}' has a clip to pose the "
                              "family with", file, options.skeleton));
  }
}

std::vector<int> CorrectiveData::members(const std::vector<int>& dataset_indices) const {
  std::vector<int> out;
  for (int index : dataset_indices) {
    for (std::size_t k = 0; k < characters_.size(); ++k) {
      if (characters_[k].dataset_index == index) out.push_back(static_cast<int>(k));
    }
  }
  return out;
}

std::vector<Eigen::Affine3d> CorrectiveData::transforms(int character, int pose) const {
  const CorrectiveCharacter& c = characters_.at(static_cast<std::size_t>(character));
  const PoseRef& p = c.poses.at(static_cast<std::size_t>(pose));
  const auto& frame = clips_[static_cast<std::size_t>(p.clip)].frames[static_cast<std::size_t>(p.frame)];
  const Eigen::Matrix4d N = c.normalisation, N_inverse = c.normalisation.inverse();
  std::vector<Eigen::Isometry3d> pose_transforms;
  pose_transforms.reserve(frame.size());
  for (std::size_t j = 0; j < frame.size(); ++j) {
    // conjugate(N⁻¹, N, ·) = N · F · N⁻¹: the game frame into this character's normalised frame.
    pose_transforms.push_back(conjugate(N_inverse, N, frame[j]) * c.bind_inverse[j]);
  }
  const Eigen::Isometry3d to_root = pose_transforms[static_cast<std::size_t>(c.root)].inverse();
  std::vector<Eigen::Affine3d> out;
  out.reserve(frame.size());
  for (const auto& t : pose_transforms) out.emplace_back((to_root * t).matrix());
  return out;
}

torch::Tensor CorrectiveData::features(int character, const Eigen::MatrixXd& posed,
                                       const std::vector<Eigen::Affine3d>& transforms) const {
  const CorrectiveCharacter& c = characters_.at(static_cast<std::size_t>(character));
  const Eigen::MatrixXd normals = geometry::vertex_normals(geometry::Mesh{posed, c.mesh.F});
  Eigen::MatrixXd joints(c.num_joints(), 3);
  for (int j = 0; j < c.num_joints(); ++j) {
    joints.row(j) = (transforms[static_cast<std::size_t>(j)] * Eigen::Vector3d(c.joints.row(j).transpose())).transpose();
  }
  const std::int64_t n = posed.rows(), width = 6 + c.num_joints();
  torch::Tensor out = torch::empty({n, width}, torch::kFloat32);
  auto a = out.accessor<float, 2>();
  for (std::int64_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      a[i][k] = static_cast<float>(posed(i, k));
      a[i][3 + k] = static_cast<float>(normals(i, k));
    }
    for (int j = 0; j < c.num_joints(); ++j) {
      a[i][6 + j] = static_cast<float>((posed.row(i) - joints.row(j)).norm());
    }
  }
  return out;
}

CorrectiveSample CorrectiveData::sample(int character, int pose) const {
  const CorrectiveCharacter& c = characters_.at(static_cast<std::size_t>(character));
  CorrectiveSample s;
  s.transforms = transforms(character, pose);
  s.lbs = geometry::lbs(c.mesh.V, c.weights, s.transforms);
  s.target = c.mush->deform(s.lbs, &s.passthrough);
  s.displacement = (s.target - s.lbs) * cm_per_unit();
  s.features = features(character, s.lbs, s.transforms);
  s.displacement_t = data::to_float(data::RowMatrixXd(s.displacement));
  return s;
}

}  // namespace skinlab::densegats

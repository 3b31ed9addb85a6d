#pragma once
/// \file
/// The corrective-deformation task of DenseGATs (Li et al. I3D 2020, Sec. 3): a character posed
/// by linear blend skinning, t(S), is corrected by a per-vertex displacement h(G) that a graph
/// network predicts from the LBS mesh. One sample is a (character, pose) pair:
///
///     input  G: the LBS mesh's graph (one-ring edges) with node attributes
///               v_i = [p_i, n_i, s_i]  (Sec. 3.1): LBS position, LBS vertex normal, and the
///               Euclidean distances to all J posed joints;
///     target  : Delta Mush(LBS mesh) − LBS mesh, per vertex, in cm at the character's height.
///
/// Our data, honestly. The paper's ground truth is artist-refined deformation of ~150
/// characters sharing a 65-joint skeleton; it is private. Ours: the 0 A.D. humans, dozens of
/// garment variants on one 46-joint biped skeleton, with the artist's own weights, posed by the
/// game's own animation clips (art/animation/biped/**.psa), and as the non-linear target
/// **Delta Mush** (geometry/delta_mush.hpp, Mancewicz et al. 2014) applied to the artist-weighted
/// LBS result: a production corrective deformer, not artist data.
///
/// Poses. Characters of one skeleton family share their clips in the game (the engine plays any
/// biped clip on any biped mesh), so the clips of every character of the family in the dataset
/// file are pooled (one copy per clip name, in file order) and every character is posed by all
/// of them: the engine's rule, pose(j) = frame(j) · bind(j)⁻¹, with the clip's global joint
/// transforms carried from its owner's normalised frame to this character's (both are
/// similarities of the game frame: G = N_this · N_owner⁻¹ · F · N_owner · N_this⁻¹) and this
/// character's own bind pose. Every `frame_stride`-th frame of each clip is used. The global
/// motion is removed: every transform is taken relative to the root joint's, so the root stays
/// at its bind pose and a walk does not walk away (errors are invariant to it; the network's
/// position inputs would not be).
///
/// A character is posed with its own bind pose, which the dataset file keeps per character
/// (PreparedCharacter::bind), so a character without a clip of its own is posed by its family's
/// clips like the others. A character without a bind pose (a file written before it was stored,
/// whose characters without clips have none) is left out with the reason (`excluded()`), never
/// posed with another character's bind.
///
/// Units: the normalised frame is 1 m tall; errors and targets are reported in cm with every
/// character scaled to `height_m` (1.75 m: the game's units are not metres, and its humans are
/// adults of one height). Positions and distances in the inputs stay in the 1 m frame.

#include <torch/torch.h>

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/geometry/delta_mush.hpp"
#include "framework/geometry/mesh.hpp"
#include "framework/geometry/skin_weights.hpp"

namespace skinlab::densegats {

/// The `corrective:` section of a DenseGATs config.
///
///     corrective:
///       skeleton: Biped          # the skeleton family whose characters and clips are used
///       frame_stride: 4          # every 4th frame of every clip
///       max_poses_per_character: 0   # 0 = all; else that many, evenly spaced over the list
///       height_m: 1.75           # cm at this height
///       delta_mush: {iterations: 10, step: 0.5}
///       # training and evaluation (corrective_task.hpp; Sec. 3.4 and 4)
///       samples_per_epoch: 400   # (character, pose) samples drawn per epoch
///       batch_size: 8            # samples per optimizer step (Sec. 3.4: 8)
///       window: 1000             # consecutive vertices per training sample (Sec. 4: 1,000); 0: all
///       eval_poses: 32           # poses per character for validation and test, evenly spaced
///       plateau: {factor: 0.75, patience: 8, min_lr: 5.0e-7}   # Sec. 3.4
///       baseline: ""             # lbs or dqs: evaluate that deformer instead of a network
struct CorrectiveOptions {
  std::string skeleton = "Biped";
  int frame_stride = 4;
  int max_poses_per_character = 0;
  double height_m = 1.75;
  geometry::DeltaMushOptions delta_mush;
  int samples_per_epoch = 400;
  int batch_size = 8;
  int window = 1000;
  int eval_poses = 32;
  double plateau_factor = 0.75;
  int plateau_patience = 8;
  double plateau_min_lr = 5e-7;
  std::string baseline;
  /// Decodes and checks the section (every field optional); errors name the file, line, key.
  static CorrectiveOptions from(const config::Node& node);
};

/// One pose of the pooled library: frame `frame` of clip `clip`.
struct PoseRef {
  int clip = 0;
  int frame = 0;
};

/// A clip of the pool: global joint transforms per frame in the game's frame (the owner's
/// normalisation undone), #frames × #J.
struct PooledClip {
  std::string name;
  std::string owner;  ///< the character whose file entry it came from
  std::vector<std::vector<Eigen::Isometry3d>> frames;
};

/// One character of the task, with what every sample of it needs precomputed.
struct CorrectiveCharacter {
  std::string name;
  int dataset_index = 0;               ///< index in the dataset file
  geometry::Mesh mesh;                 ///< rest mesh (normalised frame), faces oriented outwards
  geometry::SparseWeights weights;     ///< #V×#J artist weights
  Eigen::MatrixXd joints;              ///< #J×3 rest joint positions
  int root = 0;                        ///< the joint without a parent
  Eigen::Matrix4d normalisation = Eigen::Matrix4d::Identity();
  std::vector<Eigen::Isometry3d> bind_inverse;  ///< #J, normalised frame
  std::shared_ptr<const geometry::DeltaMush> mush;
  torch::Tensor one_ring;              ///< #E×2 int64 mesh edges (i receives from j)
  std::vector<PoseRef> poses;
  int num_vertices() const { return mesh.num_vertices(); }
  int num_joints() const { return static_cast<int>(joints.rows()); }
};

/// One (character, pose) sample. Matrices are #V×3 in the character's normalised frame, root at
/// its bind pose; displacements in cm.
struct CorrectiveSample {
  std::vector<Eigen::Affine3d> transforms;  ///< #J skinning transforms of the pose (transforms())
  Eigen::MatrixXd lbs;           ///< t(S): the artist-weighted LBS mesh
  Eigen::MatrixXd target;        ///< Delta Mush(lbs)
  Eigen::MatrixXd displacement;  ///< (target − lbs) · cm per unit: what the network predicts
  torch::Tensor features;        ///< #V×(6+J) float32 [p, n, s] of the LBS mesh (Sec. 3.1)
  torch::Tensor displacement_t;  ///< #V×3 float32, `displacement` as a tensor
  int passthrough = 0;           ///< vertices Delta Mush left at their LBS position
};

class CorrectiveData {
 public:
  /// Selects the characters of `options.skeleton` in `dataset` (read from `file`, named in
  /// messages), pools their clips and precomputes every character's Delta Mush. Characters of
  /// other families are ignored; those of the family without a bind pose are `excluded()`.
  /// Throws IoError naming the file when the family has no character with a bind pose or no
  /// clip, when the family's
  /// characters disagree on the joint count or names (naming both characters), or when a clip
  /// has another joint count than the family (naming the clip).
  CorrectiveData(const data::Dataset& dataset, const std::string& file,
                 const CorrectiveOptions& options);

  const CorrectiveOptions& options() const { return options_; }
  const std::vector<CorrectiveCharacter>& characters() const { return characters_; }
  const std::vector<PooledClip>& clips() const { return clips_; }
  /// "name: reason" for each family member left out.
  const std::vector<std::string>& excluded() const { return excluded_; }
  int num_joints() const { return num_joints_; }
  /// Input width 6 + J.
  std::int64_t feature_width() const { return 6 + num_joints_; }
  /// cm per normalised unit (height_m · 100).
  double cm_per_unit() const { return options_.height_m * 100; }

  /// Indices into characters() of the task's members among `dataset_indices` (a split part of
  /// the dataset, e.g. RunData::part("test")), in that order; other characters are skipped.
  std::vector<int> members(const std::vector<int>& dataset_indices) const;

  /// #J skinning transforms (normalised frame, relative to the bind pose, root-relative) of
  /// pose `pose` of character `character`.
  std::vector<Eigen::Affine3d> transforms(int character, int pose) const;

  /// The sample of (character, pose): LBS, Delta Mush, displacement and features.
  CorrectiveSample sample(int character, int pose) const;

  /// Node attributes [p, n, s] (Sec. 3.1) of `posed` (#V×3, the character's mesh deformed by
  /// `transforms`): the positions, the area-weighted vertex normals of the outward-oriented
  /// faces, and the distances to the posed joints T_j · joint_j. #V×(6+J) float32.
  torch::Tensor features(int character, const Eigen::MatrixXd& posed,
                         const std::vector<Eigen::Affine3d>& transforms) const;

 private:
  CorrectiveOptions options_;
  std::string file_;
  std::vector<CorrectiveCharacter> characters_;
  std::vector<PooledClip> clips_;
  std::vector<std::string> excluded_;
  int num_joints_ = 0;
};

}  // namespace skinlab::densegats

// Augmented training copies (framework/data/augment.hpp) on the bundled real 0 A.D. subset
// (datasets/zeroad/bundled, CC-BY-SA 3.0, Wildfire Games): what a copy keeps and what each kind
// does to the geometry, and through `skinlab prepare` that copies only ever train and come out
// the same for the same config.

#include "framework/data/augment.hpp"

#include <gtest/gtest.h>

#include <array>
#include <set>

#include "framework/core/registry.hpp"
#include "framework/data/preprocess.hpp"
#include "tests/bundled_dataset.hpp"
#include "tests/data/data_fixtures.hpp"
#include "tests/geometry/test_meshes.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::expect_equal;
using testing::expect_error;
using testing::TempDir;

const std::string kSource = SKINLAB_SOURCE_DIR;

/// A character of the bundled subset, as the `zeroad` builder reads it.
const datasets::SourceCharacter& bundled(const std::string& name) {
  static const std::vector<datasets::SourceCharacter> all = [] {
    std::vector<datasets::Excluded> excluded;
    const auto config =
        config::Config::parse("type: zeroad\npath: " + kSource + "/datasets/zeroad/bundled\n");
    return dataset_registry().create(config.root())->read(excluded);
  }();
  for (const auto& c : all) {
    if (c.character.name == name) return c;
  }
  throw std::runtime_error("no bundled character " + name);
}

std::vector<data::NamedDistance> euclidean() {
  const auto config = config::Config::parse("type: euclidean\n");
  return {{"euclidean", distance_registry().create(config.root())}};
}

/// `preprocess:` options from YAML (the dataset config's section).
data::PreprocessOptions options(const std::string& yaml) {
  return data::PreprocessOptions::from(config::Config::parse(yaml).root());
}

data::PreparedCharacter prepared(const std::string& name, const data::PreprocessOptions& o,
                                 int copy = -1) {
  data::PreprocessMode mode;
  mode.augment_copy = copy;
  return data::preprocess(bundled(name), euclidean(), o, mode);
}

Eigen::Vector3d face_normal(const data::PreparedCharacter& c, Eigen::Index f) {
  const Eigen::Vector3d a = c.V.row(c.F(f, 0)), b = c.V.row(c.F(f, 1)), d = c.V.row(c.F(f, 2));
  return (b - a).cross(d - a);
}

/// Σ a·(b × d) / 6 over the faces: the enclosed volume, positive when the faces face outwards.
double signed_volume(const data::PreparedCharacter& c) { return testing::signed_volume(c.V, c.F); }

Eigen::RowVector3d extent(const Eigen::MatrixXd& V) {
  return V.colwise().maxCoeff() - V.colwise().minCoeff();
}

TEST(Augment, CopyKeepsWeightsJointOrderAndBones) {
  const auto o = options(
      "augment: {copies: 1, pose: {clips: true, random_degrees: 25}, scale: [0.8, 1.25], "
      "mirror: 0.5}");
  const auto original = prepared("wolf", o);
  const auto copy = prepared("wolf", o, 0);
  EXPECT_EQ(copy.name, "wolf~aug0");
  EXPECT_EQ(copy.augmented_from, "wolf");
  EXPECT_TRUE(original.augmented_from.empty());
  EXPECT_EQ(copy.weights.nonZeros(), original.weights.nonZeros());
  EXPECT_EQ(Eigen::MatrixXd(copy.weights), Eigen::MatrixXd(original.weights));
  EXPECT_EQ(copy.joint_names, original.joint_names);
  EXPECT_EQ(copy.parents, original.parents);
  EXPECT_EQ(copy.bones, original.bones);
  EXPECT_EQ(copy.vertex_map, original.vertex_map);
  EXPECT_EQ(copy.one_ring_edges, original.one_ring_edges);  // the same mesh graph
  EXPECT_EQ(copy.source, original.source);
  EXPECT_EQ(copy.licence, original.licence);
  EXPECT_TRUE(copy.animations.empty());
  EXPECT_FALSE(original.animations.empty());
  EXPECT_FALSE(copy.V.isApprox(original.V, 1e-3)) << "the copy is deformed";
  // Still in the dataset's frame: 1 m tall, feet at 0, x/z centred.
  EXPECT_NEAR(extent(copy.V).y(), 1.0, 1e-12);
  EXPECT_NEAR(copy.V.col(1).minCoeff(), 0.0, 1e-12);
  EXPECT_NEAR(copy.V.col(0).maxCoeff() + copy.V.col(0).minCoeff(), 0.0, 1e-12);
}

TEST(Augment, PureMirrorReflectsXAndKeepsNormalsOutward) {
  const auto o = options("augment: {copies: 1, mirror: 1.0}");
  const auto original = prepared("wolf", o);
  const auto copy = prepared("wolf", o, 0);
  ASSERT_EQ(copy.V.rows(), original.V.rows());
  EXPECT_LT((copy.V.col(0) + original.V.col(0)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((copy.V.rightCols(2) - original.V.rightCols(2)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((copy.joints.col(0) + original.joints.col(0)).cwiseAbs().maxCoeff(), 1e-12);
  // Every face's normal is its original's reflected, so it faces the same side of the surface.
  ASSERT_EQ(copy.F.rows(), original.F.rows());
  const Eigen::Vector3d reflect(-1, 1, 1);
  for (Eigen::Index f = 0; f < copy.F.rows(); ++f) {
    const Eigen::Vector3d n = face_normal(original, f).cwiseProduct(reflect);
    ASSERT_LT((face_normal(copy, f) - n).norm(), 1e-12 + 1e-9 * n.norm()) << "face " << f;
  }
  const double volume = signed_volume(original);
  ASSERT_GT(std::abs(volume), 1e-4);
  EXPECT_NEAR(signed_volume(copy), volume, 1e-9 * std::abs(volume));
}

TEST(Augment, PoseWithZeroRotationIsTheOriginal) {
  // Extended leaf bones too, so the leaf tips are checked; no clips, so the random pose is used.
  const auto o = options(
      "leaf_bones: extended\naugment: {copies: 1, pose: {clips: false, random_degrees: 0, "
      "random_fraction: 1}}");
  auto original = prepared("wolf", o);
  const auto copy = prepared("wolf", o, 0);
  ASSERT_GT(original.leaf_tips.rows(), 0);
  original.name = copy.name;
  original.augmented_from = copy.augmented_from;
  original.animations.clear();  // an augmented copy has neither clips nor a bind pose
  original.bind.clear();
  expect_equal(copy, original);
}

TEST(Augment, AnisotropicScaleScalesTheBoundingBoxByTheDrawnFactors) {
  data::AugmentOptions o;
  o.copies = 1;
  o.scale = true;
  o.scale_min = 0.5;
  o.scale_max = 2.0;
  const auto original = prepared("goat", options("{}"));
  const geometry::Skeleton skeleton = original.rig();
  const data::Augmentation a =
      data::draw_augmentation(o, "goat", 0, skeleton, {}, Eigen::Matrix4d::Identity());
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_GE(a.scale(axis), 0.5);
    EXPECT_LE(a.scale(axis), 2.0);
  }
  EXPECT_NE(a.scale.x(), a.scale.y());
  EXPECT_TRUE(a.pose.empty());
  EXPECT_FALSE(a.mirror);

  geometry::Mesh mesh{original.V, original.F};
  geometry::Skeleton moved = skeleton;
  data::apply_augmentation(a, original.weights, mesh, moved);
  const Eigen::RowVector3d expected = extent(original.V).cwiseProduct(a.scale.transpose());
  EXPECT_LT((extent(mesh.V) - expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((extent(moved.positions) - extent(skeleton.positions).cwiseProduct(a.scale.transpose()))
                .cwiseAbs()
                .maxCoeff(),
            1e-12);

  // Prepared, the copy is normalised to 1 m tall again: the proportions carry the factors.
  auto prepare = options("augment: {copies: 1, scale: [0.5, 2.0]}");
  const auto copy = prepared("goat", prepare, 0);
  const Eigen::RowVector3d e0 = extent(original.V), e1 = extent(copy.V);
  EXPECT_NEAR(e1.y(), 1.0, 1e-12);
  EXPECT_NEAR(e1.x() / e1.y(), e0.x() / e0.y() * a.scale.x() / a.scale.y(), 1e-9);
  EXPECT_NEAR(e1.z() / e1.y(), e0.z() / e0.y() * a.scale.z() / a.scale.y(), 1e-9);
}

TEST(Augment, ClipPoseMovesTheJointsToAFrameAndLeafTipsFollow) {
  const auto& wolf = bundled("wolf");
  const auto o = options("leaf_bones: extended\naugment: {copies: 1, pose: {clips: true}}");
  const auto original = prepared("wolf", o);
  const geometry::Skeleton skeleton = original.rig();
  const Eigen::Matrix4d frame = original.normalisation;
  const data::Augmentation a =
      data::draw_augmentation(o.augment, "wolf", 0, skeleton, wolf.animations, frame);
  ASSERT_EQ(a.pose_source.rfind("clip '", 0), 0u) << a.pose_source;
  ASSERT_EQ(a.pose.size(), static_cast<std::size_t>(skeleton.num_joints()));

  geometry::Mesh mesh{original.V, original.F};
  geometry::Skeleton posed = skeleton;
  data::apply_augmentation(a, original.weights, mesh, posed);
  // The clip's frame of that name: every joint at its global transform's origin (0 A.D. joints
  // sit at their bind transform's origin), in the normalised frame.
  const std::string clip_name = a.pose_source.substr(6, a.pose_source.find("' frame ") - 6);
  const int f = std::stoi(a.pose_source.substr(a.pose_source.find(" frame ") + 7));
  const datasets::Animation* clip = nullptr;
  for (const auto& c : wolf.animations) {
    if (c.name == clip_name) clip = &c;
  }
  ASSERT_NE(clip, nullptr) << clip_name;
  const Eigen::Affine3d to_frame(frame);
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const Eigen::Vector3d expected = to_frame * clip->frames[f][j].translation();
    EXPECT_LT((posed.positions.row(j).transpose() - expected).norm(), 1e-6) << "joint " << j;
  }
  // A leaf's bone turns with its leaf: same length, from the leaf's new position.
  int moved = 0;
  const auto children = skeleton.children();
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    if (!children[j].empty()) continue;
    const double before = (skeleton.leaf_tips.row(j) - skeleton.positions.row(j)).norm();
    const double after = (posed.leaf_tips.row(j) - posed.positions.row(j)).norm();
    EXPECT_NEAR(after, before, 1e-9) << "leaf " << j;
    moved += (posed.leaf_tips.row(j) - skeleton.leaf_tips.row(j)).norm() > 1e-3 ? 1 : 0;
  }
  EXPECT_GT(moved, 0);
}

TEST(Augment, CharacterWithoutClipsTakesARandomPose) {
  const auto o = options("augment: {copies: 1, pose: {clips: true, random_degrees: 25}}");
  const auto original = prepared("cattle_male_a", o);
  ASSERT_TRUE(bundled("cattle_male_a").animations.empty());
  const data::Augmentation a = data::draw_augmentation(
      o.augment, "cattle_male_a", 0, original.rig(), {}, Eigen::Matrix4d::Identity());
  EXPECT_EQ(a.pose_source, "random");
  // Without random_degrees such a character keeps its bind pose.
  const auto clips_only = options("augment: {copies: 1, pose: {clips: true}}");
  EXPECT_TRUE(data::draw_augmentation(clips_only.augment, "cattle_male_a", 0, original.rig(), {},
                                      Eigen::Matrix4d::Identity())
                  .pose.empty());
}

TEST(Augment, DrawsDependOnSeedAndNameAndEachKindHasItsOwnStream) {
  const auto all = options(
      "augment: {copies: 2, seed: 5, pose: {random_degrees: 25}, scale: [0.8, 1.25], "
      "mirror: 0.5}");
  const auto scale_only = options("augment: {copies: 2, seed: 5, scale: [0.8, 1.25]}");
  const geometry::Skeleton skeleton = prepared("goat", options("{}")).rig();
  const auto draw = [&](const data::PreprocessOptions& o, const std::string& name, int copy) {
    return data::draw_augmentation(o.augment, name, copy, skeleton, {},
                                   Eigen::Matrix4d::Identity());
  };
  EXPECT_EQ(draw(all, "goat", 1).scale, draw(all, "goat", 1).scale);
  EXPECT_EQ(draw(all, "goat", 1).scale, draw(scale_only, "goat", 1).scale);
  EXPECT_NE(draw(all, "goat", 0).scale, draw(all, "goat", 1).scale);
  EXPECT_NE(draw(all, "goat", 0).scale, draw(all, "sheep", 0).scale);
  auto reseeded = all;
  reseeded.augment.seed = 6;
  EXPECT_NE(draw(all, "goat", 0).scale, draw(reseeded, "goat", 0).scale);
}

TEST(Augment, BadConfigValuesNameTheKey) {
  TempDir dir;
  const auto load = [&](const std::string& augment) {
    const auto file = dir.write(
        "augmented.yaml", "_base_: " + kSource + "/configs/datasets/zeroad_bundled.yaml\n" +
                              "preprocess:\n  augment: " + augment + "\nsources: [{type: zeroad, " +
                              "path: " + kSource + "/datasets/zeroad/bundled}]\n");
    return data::PrepareConfig::from(config::Config::load(file));
  };
  // (augment map, key path, what the message says); every one is on the file's line 3.
  const std::vector<std::array<std::string, 3>> cases = {
      {"{copies: -1, mirror: 0.5}", "preprocess.augment.copies", "≥ 0"},
      {"{copies: 1, scale: [1.25, 0.8]}", "preprocess.augment.scale", "min ≤ max"},
      {"{copies: 1, scale: [0, 2]}", "preprocess.augment.scale", "positive"},
      {"{copies: 1, scale: [0.8]}", "preprocess.augment.scale", "[min, max]"},
      {"{copies: 1, mirror: 1.5}", "preprocess.augment.mirror", "[0, 1]"},
      {"{copies: 1, mirror: -0.1}", "preprocess.augment.mirror", "[0, 1]"},
      {"{copies: 1, pose: {random_degrees: -5}}", "preprocess.augment.pose.random_degrees",
       "[0, 180]"},
      {"{copies: 1, pose: {}}", "preprocess.augment.pose", "clips: true"},
      {"{copies: 2}", "preprocess.augment.copies", "no kind of augmentation"},
      {"{copies: 1, mirorr: 0.5}", "mirorr", "did you mean 'mirror'"},
  };
  for (const auto& [augment, key, message] : cases) {
    SCOPED_TRACE(augment);
    expect_error<ConfigError>([&] { load(augment); }, {"augmented.yaml:3", key, message});
  }
  // Absent, or zero copies: off.
  EXPECT_EQ(load("{}").preprocess.augment.copies, 0);
  EXPECT_EQ(data::PreprocessOptions::from(
                config::Config::load(kSource + "/configs/datasets/zeroad_bundled.yaml")
                    .root()["preprocess"])
                .augment.copies,
            0);
}

// ---- through `skinlab prepare` ------------------------------------------------------------------

// The bundled subset (with its random and held-out-skeleton splits), Euclidean distance only,
// prepared on first use by the tests that need it.

const std::string kBundledConfig = "configs/datasets/zeroad_bundled.yaml";
const std::string kEuclidean = "distances=[{type: euclidean}]";
const std::string kAugment =
    "preprocess.augment={copies: 1, seed: 3, pose: {clips: true, random_degrees: 25}, "
    "scale: [0.8, 1.25], mirror: 0.5}";

const TempDir& prepared_dir() {
  static const TempDir dir;
  return dir;
}

/// Without augmentation.
const data::Dataset& plain() {
  static const data::Dataset d = testing::prepare_bundled(
      kBundledConfig, (prepared_dir() / "plain.h5").string(), {kEuclidean});
  return d;
}

/// With one copy of every character some split trains on.
const data::Dataset& augmented() {
  static const data::Dataset d = testing::prepare_bundled(
      kBundledConfig, (prepared_dir() / "augmented.h5").string(), {kEuclidean, kAugment});
  return d;
}

/// The same config again, in two shards on one thread each (another scheduling, and the
/// sharded path), then merged.
struct Sharded {
  data::PrepareReport merge;
  data::Dataset dataset;
};
const Sharded& sharded() {
  static const Sharded s = [] {
    const std::string out = (prepared_dir() / "sharded.h5").string();
    const auto config = testing::bundled_config(kBundledConfig, out, {kEuclidean, kAugment});
    data::PrepareOptions o;
    o.threads = 1;
    o.progress = false;
    o.shard_count = 2;
    for (o.shard_index = 0; o.shard_index < 2; ++o.shard_index) data::prepare_dataset(config, o);
    o.shard_index = 0;
    o.shard_count = 1;
    Sharded r;
    r.merge = data::prepare_dataset(config, o);
    r.dataset = data::read_dataset(out);
    return r;
  }();
  return s;
}

TEST(AugmentedPreparation, OriginalsAndTheirSplitsAreThoseWithoutAugmentation) {
  const auto& p = plain();
  const auto& a = augmented();
  ASSERT_GT(a.characters.size(), p.characters.size());
  for (std::size_t i = 0; i < p.characters.size(); ++i) {
    EXPECT_EQ(a.characters[i].name, p.characters[i].name);
    EXPECT_FALSE(a.characters[i].is_augmented_copy());
    EXPECT_EQ(a.characters[i].V, p.characters[i].V);
    EXPECT_EQ(a.characters[i].distances.at("euclidean").D,
              p.characters[i].distances.at("euclidean").D);
  }
  for (std::size_t i = p.characters.size(); i < a.characters.size(); ++i) {
    EXPECT_TRUE(a.characters[i].is_augmented_copy()) << a.characters[i].name;
  }
  ASSERT_EQ(a.splits.size(), p.splits.size());
  ASSERT_TRUE(a.splits.count("heldout_skeleton"));
  for (const auto& [name, split] : p.splits) {
    const auto& s = a.splits.at(name);
    EXPECT_EQ(s.val, split.val) << name;
    EXPECT_EQ(s.test, split.test) << name;
    const std::vector<int> originals(s.train.begin(), s.train.begin() + split.train.size());
    EXPECT_EQ(originals, split.train) << name;
  }
}

TEST(AugmentedPreparation, CopiesOnlyTrainAndOnlyForCharactersSomeSplitTrainsOn) {
  const auto& a = augmented();
  std::map<std::string, int> index;
  for (std::size_t i = 0; i < a.characters.size(); ++i)
    index[a.characters[i].name] = static_cast<int>(i);
  std::set<int> trained_somewhere;
  for (const auto& [name, split] : a.splits) {
    for (int i : split.train) {
      if (!a.characters[static_cast<std::size_t>(i)].is_augmented_copy())
        trained_somewhere.insert(i);
    }
  }
  // Exactly one copy (copies: 1) of every character some split trains on, and of no other.
  std::set<int> copied;
  for (const auto& c : a.characters) {
    if (!c.is_augmented_copy()) continue;
    ASSERT_TRUE(index.count(c.augmented_from)) << c.name;
    const int original = index.at(c.augmented_from);
    EXPECT_EQ(c.name, c.augmented_from + "~aug0");
    EXPECT_EQ(c.group, a.characters[static_cast<std::size_t>(original)].group);
    EXPECT_TRUE(copied.insert(original).second);
  }
  EXPECT_EQ(copied, trained_somewhere);
  // In every split a copy trains exactly when its original does, is never in val or test, and
  // shares no variant group with a character the split validates or tests on.
  for (const auto& [name, split] : a.splits) {
    const std::set<int> train(split.train.begin(), split.train.end());
    std::set<std::string> held_groups;
    for (const auto* part : {&split.val, &split.test}) {
      for (int i : *part) {
        EXPECT_FALSE(a.characters[static_cast<std::size_t>(i)].is_augmented_copy()) << name;
        held_groups.insert(a.characters[static_cast<std::size_t>(i)].group);
      }
    }
    for (std::size_t i = 0; i < a.characters.size(); ++i) {
      const auto& c = a.characters[i];
      if (!c.is_augmented_copy()) continue;
      const bool original_trains = train.count(index.at(c.augmented_from)) > 0;
      EXPECT_EQ(train.count(static_cast<int>(i)) > 0, original_trains) << name << ": " << c.name;
      if (original_trains) {
        EXPECT_FALSE(held_groups.count(c.group)) << name << ": " << c.name;
      }
    }
  }
}

TEST(AugmentedPreparation, SameSeedGivesTheSameFileContentsInShardsToo) {
  const auto& a = augmented();
  const auto& b = sharded().dataset;
  // The shards made every character and copy; the merge only collected them.
  EXPECT_EQ(sharded().merge.computed, 0u);
  EXPECT_EQ(sharded().merge.characters, a.characters.size());
  ASSERT_EQ(a.characters.size(), b.characters.size());
  for (std::size_t i = 0; i < a.characters.size(); ++i) {
    SCOPED_TRACE(a.characters[i].name);
    expect_equal(a.characters[i], b.characters[i]);
  }
  ASSERT_EQ(a.splits.size(), b.splits.size());
  for (const auto& [name, split] : a.splits) {
    EXPECT_EQ(split.train, b.splits.at(name).train);
    EXPECT_EQ(split.val, b.splits.at(name).val);
    EXPECT_EQ(split.test, b.splits.at(name).test);
  }
  EXPECT_EQ(a.preparation, b.preparation);
  EXPECT_EQ(sharded().merge.copies, a.characters.size() - plain().characters.size());
  EXPECT_NE(a.preparation.find("augment"), std::string::npos);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

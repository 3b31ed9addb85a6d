// DenseGATs' corrective-deformation data on the bundled real 0 A.D. bipeds (f_dress,
// m_armor_pants, m_tunic_short with their own game clips): the pose rule reproduces the
// engine's skinning of a character's own clip, the root stays at its bind pose, clips carry over
// between characters of the family, the features are [p, n, s] of the LBS mesh, the target is
// Delta Mush's correction, and bad data is an error naming the file and the character.
#include "experiments/densegats/corrective_data.hpp"

#include <gtest/gtest.h>

#include <set>

#include "framework/core/error.hpp"
#include "framework/geometry/lbs.hpp"
#include "tests/densegats/densegats_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::densegats {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using CorrectiveDataTest = BundledBipeds;

TEST_F(CorrectiveDataTest, TheBundledBipedsShareTheirClips) {
  const CorrectiveData data(*dataset_, file_, options());
  ASSERT_EQ(data.characters().size(), 3u);
  EXPECT_TRUE(data.excluded().empty());
  EXPECT_EQ(data.num_joints(), 46);
  EXPECT_EQ(data.feature_width(), 52);
  std::set<std::string> names;
  for (const auto& clip : data.clips()) names.insert(clip.name);
  EXPECT_EQ(names.size(), data.clips().size());  // one copy per clip name
  EXPECT_EQ(data.clips().size(), 10u);  // 11 clips on the three characters, one shared
  // Every character gets every pose of the pool.
  for (const auto& c : data.characters()) EXPECT_EQ(c.poses.size(), data.characters()[0].poses.size());
  // The split has one garment per part.
  const data::Split& split = dataset_->splits.at("random");
  EXPECT_EQ(data.members(split.train).size() + data.members(split.val).size() +
                data.members(split.test).size(),
            3u);
}

TEST_F(CorrectiveDataTest, OwnClipsFollowTheEngineRuleAndTheRootStaysAtItsBindPose) {
  const CorrectiveData data(*dataset_, file_, options());
  for (int c = 0; c < static_cast<int>(data.characters().size()); ++c) {
    const CorrectiveCharacter& ch = data.characters()[static_cast<std::size_t>(c)];
    const data::PreparedCharacter& prepared = dataset_->characters[static_cast<std::size_t>(ch.dataset_index)];
    const data::AnimationData& own = prepared.animations.front();
    // Find a pose of this character's own first clip and recompute the engine's
    // frame(j) · bind(j)⁻¹ from the stored floats, relative to the root.
    int pose = -1;
    for (std::size_t p = 0; p < ch.poses.size(); ++p) {
      if (data.clips()[static_cast<std::size_t>(ch.poses[p].clip)].name == own.name) {
        pose = static_cast<int>(p);
        break;
      }
    }
    ASSERT_GE(pose, 0) << ch.name;
    const int frame = ch.poses[static_cast<std::size_t>(pose)].frame;
    auto matrix = [](const float* m) {
      Eigen::Matrix4d out = Eigen::Matrix4d::Identity();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) out(i, j) = m[4 * i + j];
      return out;
    };
    const auto T = data.transforms(c, pose);
    const auto engine = [&](int j) {
      return Eigen::Matrix4d(
          matrix(own.frames.data() + (static_cast<std::size_t>(frame) * 46 + j) * 12) *
          matrix(own.bind.data() + static_cast<std::size_t>(j) * 12).inverse());
    };
    const Eigen::Matrix4d root_inverse = engine(ch.root).inverse();
    for (int j = 0; j < 46; ++j) {
      EXPECT_TRUE(T[static_cast<std::size_t>(j)].matrix().isApprox(root_inverse * engine(j), 1e-4))
          << ch.name << " joint " << j;
    }
    EXPECT_TRUE(T[static_cast<std::size_t>(ch.root)].matrix().isIdentity(1e-9)) << ch.name;
  }
}

TEST_F(CorrectiveDataTest, SamplesAreTheLbsMeshItsFeaturesAndDeltaMushsCorrection) {
  const CorrectiveData data(*dataset_, file_, options());
  for (int c = 0; c < static_cast<int>(data.characters().size()); ++c) {
    const CorrectiveCharacter& ch = data.characters()[static_cast<std::size_t>(c)];
    // A pose of a clip owned by another character: clips carry over within the family.
    int pose = -1;
    for (std::size_t p = 0; p < ch.poses.size() && pose < 0; ++p) {
      if (data.clips()[static_cast<std::size_t>(ch.poses[p].clip)].owner != ch.name) pose = static_cast<int>(p);
    }
    ASSERT_GE(pose, 0) << ch.name;
    const CorrectiveSample s = data.sample(c, pose);
    const auto T = data.transforms(c, pose);
    ASSERT_EQ(s.transforms.size(), T.size());
    for (std::size_t j = 0; j < T.size(); ++j) EXPECT_TRUE(s.transforms[j].isApprox(T[j], 1e-15));
    EXPECT_TRUE(s.lbs.isApprox(geometry::lbs(ch.mesh.V, ch.weights, T), 1e-12));
    EXPECT_TRUE(s.target.isApprox(ch.mush->deform(s.lbs), 1e-12));
    EXPECT_TRUE(s.displacement.isApprox((s.target - s.lbs) * 175.0, 1e-12));
    // Posed, not the rest mesh; the correction is real but small next to a 1.75 m body.
    EXPECT_GT((s.lbs - ch.mesh.V).rowwise().norm().maxCoeff(), 0.02) << ch.name;
    const double mean_cm = s.displacement.rowwise().norm().mean();
    EXPECT_GT(mean_cm, 0.01) << ch.name;
    EXPECT_LT(s.displacement.rowwise().norm().maxCoeff(), 20.0) << ch.name;
    // Only vertices without a rest frame (m_tunic_short: 96 on faces whose normals cancel) keep
    // their LBS position.
    EXPECT_EQ(s.passthrough, ch.mush->passthrough()) << ch.name;
    EXPECT_LT(s.passthrough, ch.num_vertices() / 10) << ch.name;

    ASSERT_EQ(s.features.sizes(), (std::vector<std::int64_t>{ch.num_vertices(), 52}));
    EXPECT_TRUE(torch::isfinite(s.features).all().item<bool>());
    const int v = ch.num_vertices() / 2, j = 7;
    const auto f = s.features.accessor<float, 2>();
    EXPECT_NEAR(f[v][0], s.lbs(v, 0), 1e-6);
    const Eigen::Vector3d joint = T[j] * Eigen::Vector3d(ch.joints.row(j).transpose());
    EXPECT_NEAR(f[v][6 + j], (s.lbs.row(v).transpose() - joint).norm(), 1e-5);
    const double normal = std::sqrt(f[v][3] * f[v][3] + f[v][4] * f[v][4] + f[v][5] * f[v][5]);
    EXPECT_NEAR(normal, 1.0, 1e-5);
    ASSERT_EQ(s.displacement_t.sizes(), (std::vector<std::int64_t>{ch.num_vertices(), 3}));
  }
}

TEST_F(CorrectiveDataTest, PosesAreStridedAndCapped) {
  const CorrectiveData all(*dataset_, file_, options(1)), strided(*dataset_, file_, options(4));
  std::size_t frames = 0, expected_strided = 0;
  for (const auto& clip : all.clips()) {
    frames += clip.frames.size();
    expected_strided += (clip.frames.size() + 3) / 4;
  }
  EXPECT_EQ(all.characters()[0].poses.size(), frames);
  EXPECT_EQ(strided.characters()[0].poses.size(), expected_strided);
  CorrectiveOptions capped = options(1);
  capped.max_poses_per_character = 10;
  EXPECT_EQ(CorrectiveData(*dataset_, file_, capped).characters()[0].poses.size(), 10u);
}

TEST_F(CorrectiveDataTest, EveryCharacterKeepsItsOwnBindPoseInTheFile) {
  for (const auto& c : dataset_->characters) {
    ASSERT_EQ(c.bind.size(), static_cast<std::size_t>(12 * c.num_joints())) << c.name;
    ASSERT_FALSE(c.animations.empty()) << c.name;
    // The same transforms as its clips carry (both from the PMD's bind pose).
    EXPECT_EQ(c.bind, c.animations.front().bind) << c.name;
    // Stored conjugated into the normalised frame (N·B·N⁻¹), so each maps the image of the
    // source frame's origin, N·0, to its joint: N·B·N⁻¹·(N·0) = N·(B·0).
    const Eigen::Vector3d origin = c.normalisation.topRightCorner<3, 1>();
    for (int j = 0; j < c.num_joints(); ++j) {
      const Eigen::Vector3d at = data::joint_transform(c.bind.data() + 12 * j) * origin;
      EXPECT_LT((at - c.joints.row(j).transpose()).norm(), 1e-5) << c.name << " joint " << j;
    }
  }
}

TEST_F(CorrectiveDataTest, ACharacterWithoutAClipIsPosedByItsFamilysClipsWithItsOwnBindPose) {
  const CorrectiveData all(*dataset_, file_, options());
  data::Dataset copy = *dataset_;
  const std::string name = copy.characters[0].name;
  copy.characters[0].animations.clear();
  const CorrectiveData data(copy, file_, options());
  ASSERT_EQ(data.characters().size(), 3u);
  EXPECT_TRUE(data.excluded().empty());
  const CorrectiveCharacter& without = data.characters()[0];
  EXPECT_EQ(without.name, name);
  EXPECT_EQ(without.poses.size(), data.characters()[1].poses.size());
  for (std::size_t j = 0; j < without.bind_inverse.size(); ++j) {
    EXPECT_TRUE(without.bind_inverse[j].isApprox(all.characters()[0].bind_inverse[j], 1e-12)) << j;
  }

  // Without any bind pose (a file written before they were stored), it is left out, named.
  copy.characters[0].bind.clear();
  const CorrectiveData left_out(copy, file_, options());
  EXPECT_EQ(left_out.characters().size(), 2u);
  ASSERT_EQ(left_out.excluded().size(), 1u);
  EXPECT_NE(left_out.excluded()[0].find(name + ": no bind pose in the file"), std::string::npos);

  for (auto& c : copy.characters) c.animations.clear();
  expect_error<IoError>([&] { CorrectiveData(copy, file_, options()); },
                        {file_, "no character of skeleton family 'Biped' has a clip"});
  for (auto& c : copy.characters) c.bind.clear();
  expect_error<IoError>([&] { CorrectiveData(copy, file_, options()); },
                        {file_, "no character of skeleton family 'Biped' has a bind pose"});
  CorrectiveOptions horse = options();
  horse.skeleton = "Horse";
  expect_error<IoError>([&] { CorrectiveData(*dataset_, file_, horse); },
                        {file_, "no character of skeleton family 'Horse'"});
}

TEST_F(CorrectiveDataTest, DifferentJointsInOneFamilyAreAnError) {
  data::Dataset copy = *dataset_;
  copy.characters[1].joint_names[3] = "renamed";
  expect_error<IoError>([&] { CorrectiveData(copy, file_, options()); },
                        {file_, copy.characters[0].name, copy.characters[1].name, "different joints"});
}

TEST(CorrectiveOptions, AreValidated) {
  const auto parse = [](const std::string& yaml) {
    return CorrectiveOptions::from(config::Config::parse(yaml).root());
  };
  EXPECT_EQ(parse("{frame_stride: 2, delta_mush: {iterations: 5}}").delta_mush.iterations, 5);
  EXPECT_THROW(parse("{frame_stride: 0}"), ConfigError);
  EXPECT_THROW(parse("{height_m: -1}"), ConfigError);
  EXPECT_THROW(parse("{delta_mush: {step: 2}}"), ConfigError);
  EXPECT_THROW(parse("{delta_mush: {iteration: 2}}"), ConfigError);
  EXPECT_THROW(parse("{skeletons: Biped}"), ConfigError);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::densegats

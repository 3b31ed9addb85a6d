// Preprocessing (HeterSkinNet Sec. 4.1) on the real Minetest player, checked against naive
// recomputations; and the `folder` builder.

#include "framework/data/preprocess.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "datasets/folder/folder.hpp"
#include "framework/core/registry.hpp"
#include "framework/geometry/normalize.hpp"
#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/rig_io.hpp"
#include "tests/data/data_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::TempDir;

std::vector<data::NamedDistance> euclidean() {
  const auto node = config::Config::parse("type: euclidean").root();
  return {{"euclidean", distance_registry().create(node)}};
}

class MinetestPreprocess : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    source_ = new datasets::SourceCharacter(testing::minetest_player());
    prepared_ = new data::PreparedCharacter(data::preprocess(*source_, euclidean()));
  }
  static void TearDownTestSuite() {
    delete source_;
    delete prepared_;
  }
  static datasets::SourceCharacter* source_;
  static data::PreparedCharacter* prepared_;
};
datasets::SourceCharacter* MinetestPreprocess::source_ = nullptr;
data::PreparedCharacter* MinetestPreprocess::prepared_ = nullptr;

TEST_F(MinetestPreprocess, CountsAfterMergeAndSubdivision) {
  const auto& src = source_->character;
  const auto& c = *prepared_;
  ASSERT_EQ(c.vertex_map.size(), static_cast<std::size_t>(src.mesh.num_vertices()));
  const int merged = *std::max_element(c.vertex_map.begin(), c.vertex_map.end()) + 1;
  const std::set<int> distinct(c.vertex_map.begin(), c.vertex_map.end());
  EXPECT_EQ(static_cast<int>(distinct.size()), merged) << "merged vertices are 0..n-1";
  EXPECT_LE(merged, src.mesh.num_vertices());
  // Minetest's player has fewer than 1K vertices, so it is subdivided into 1K..5K.
  ASSERT_LT(src.mesh.num_vertices(), 1000);
  EXPECT_GE(c.subdivision_levels, 1);
  EXPECT_GE(c.num_vertices(), 1000);
  EXPECT_LE(c.num_vertices(), 5000);
  // Each 1-to-4 step quadruples the faces kept by the merge.
  EXPECT_EQ(c.F.rows() % (1 << (2 * c.subdivision_levels)), 0);
  // Original vertices keep their (normalised) positions at their mapped index.
  geometry::Character normalised = src;
  const geometry::Similarity sim = geometry::normalize(normalised);
  EXPECT_TRUE(c.normalisation.isApprox(sim.matrix()));
  for (int i = 0; i < src.mesh.num_vertices(); ++i) {
    ASSERT_EQ(c.V.row(c.vertex_map[i]), normalised.mesh.V.row(i)) << "vertex " << i;
  }
  EXPECT_NEAR(c.V.col(1).maxCoeff() - c.V.col(1).minCoeff(), 1.0, 1e-9) << "1 m tall";
  EXPECT_EQ(c.num_joints(), src.skeleton.num_joints());
  EXPECT_EQ(c.num_bones(), static_cast<int>(src.skeleton.bones().size()));
}

TEST_F(MinetestPreprocess, WeightRowsSumToOne) {
  const auto& W = prepared_->weights;
  ASSERT_EQ(W.rows(), prepared_->num_vertices());
  ASSERT_EQ(W.cols(), prepared_->num_joints());
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    double sum = 0;
    for (geometry::SparseWeights::InnerIterator it(W, v); it; ++it) {
      EXPECT_GE(it.value(), 0);
      sum += it.value();
    }
    ASSERT_NEAR(sum, 1.0, 1e-9) << "vertex " << v;
  }
}

TEST_F(MinetestPreprocess, TopKIsSortedAndNearest) {
  const auto& d = prepared_->distances.at("euclidean");
  ASSERT_EQ(d.topk_index.cols(), 3);
  ASSERT_EQ(d.D.rows(), prepared_->num_vertices());
  ASSERT_EQ(d.D.cols(), prepared_->num_bones());
  for (Eigen::Index v = 0; v < d.D.rows(); ++v) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(d.topk_distance(v, k), d.D(v, d.topk_index(v, k)));
      if (k > 0) {
        ASSERT_LE(d.topk_distance(v, k - 1), d.topk_distance(v, k));
      }
    }
    // No bone outside the top-K is nearer than the K-th.
    for (Eigen::Index b = 0; b < d.D.cols(); ++b) {
      const bool in = (d.topk_index.row(v).array() == b).any();
      if (!in) {
        ASSERT_GE(d.D(v, b), d.topk_distance(v, 2)) << "vertex " << v << " bone " << b;
      }
    }
  }
}

TEST_F(MinetestPreprocess, TargetsMatchNaiveRigNetRule) {
  const auto& c = *prepared_;
  const auto& d = c.distances.at("euclidean");
  const Eigen::MatrixXd W = Eigen::MatrixXd(c.weights);
  double max_lost = 0;
  for (Eigen::Index v = 0; v < d.D.rows(); ++v) {
    double sum = 0;
    for (int k = 0; k < d.topk_index.cols(); ++k) {
      const int b = d.topk_index(v, k);
      const int j = c.bones(b, 0);
      // Naive: bone b gets joint j's weight iff it is the nearest bone starting at j (first
      // such bone on ties).
      int nearest = -1;
      for (int o = 0; o < c.num_bones(); ++o) {
        if (c.bones(o, 0) == j && (nearest < 0 || d.D(v, o) < d.D(v, nearest))) nearest = o;
      }
      const double expected = nearest == b ? W(v, j) : 0.0;
      ASSERT_NEAR(d.targets(v, k), expected, 1e-6) << "vertex " << v << " candidate " << k;
      sum += d.targets(v, k);
    }
    ASSERT_LE(sum, 1.0 + 1e-6) << "vertex " << v;
    max_lost = std::max(max_lost, 1.0 - sum);
  }
  EXPECT_GT(max_lost, 0.0) << "some weight lies outside the top 3 on a real character";
}

TEST_F(MinetestPreprocess, GraphAndLaplacian) {
  const auto& c = *prepared_;
  ASSERT_GT(c.one_ring_edges.rows(), 0);
  EXPECT_EQ(c.one_ring_edges.rows() % 2, 0) << "both directions of every edge";
  std::vector<int> per_vertex(c.num_vertices(), 0);
  for (Eigen::Index e = 0; e < c.geodesic_edges.rows(); ++e) {
    ASSERT_NE(c.geodesic_edges(e, 0), c.geodesic_edges(e, 1));
    ++per_vertex[c.geodesic_edges(e, 0)];
  }
  EXPECT_LE(*std::max_element(per_vertex.begin(), per_vertex.end()), 10);
  std::vector<double> row_sum(c.num_vertices(), 0.0);
  for (Eigen::Index n = 0; n < c.laplacian_indices.rows(); ++n) {
    row_sum[c.laplacian_indices(n, 0)] += c.laplacian_values[n];
  }
  for (double s : row_sum) ASSERT_NEAR(s, 0.0, 1e-9);
  std::set<int> connected;
  for (Eigen::Index e = 0; e < c.one_ring_edges.rows(); ++e)
    connected.insert(c.one_ring_edges(e, 0));
  EXPECT_EQ(c.laplacian_indices.rows(),
            c.one_ring_edges.rows() + static_cast<Eigen::Index>(connected.size()))
      << "uniform Laplacian: one entry per directed edge plus the diagonal of connected vertices";
  EXPECT_EQ(c.source, "folder");
  EXPECT_EQ(c.licence, "CC-BY-SA-3.0");
}

TEST(BoneWeights, BranchingJointGoesToNearestBone) {
  // root(0) → a(1), root → b(2): bones (0,1), (1,1 helper), (0,2), (2,2 helper).
  geometry::Skeleton s;
  s.names = {"root", "a", "b"};
  s.parents = {-1, 0, 0};
  s.positions = Eigen::MatrixXd::Zero(3, 3);
  geometry::SparseWeights W(2, 3);
  W.insert(0, 0) = 0.6;
  W.insert(0, 1) = 0.4;
  W.insert(1, 0) = 1.0;
  Eigen::MatrixXd D(2, 4);
  D << 0.3, 0.1, 0.2, 0.5,  // vertex 0: bone 2 nearer than bone 0 among root's bones
      0.2, 0.1, 0.2, 0.5;   // vertex 1: tie between bones 0 and 2 → bone 0
  const Eigen::MatrixXd B = data::bone_weights(W, s, D);
  Eigen::MatrixXd expected(2, 4);
  expected << 0, 0.4, 0.6, 0, 1.0, 0, 0, 0;
  EXPECT_TRUE(B.isApprox(expected)) << B;
  data::RowMatrixXi index;
  data::RowMatrixXf distance;
  data::top_k_bones(D, 3, index, distance);
  EXPECT_EQ(index.row(0), (Eigen::RowVector3i() << 1, 2, 0).finished());
  EXPECT_EQ(index.row(1), (Eigen::RowVector3i() << 1, 0, 2).finished());
  data::top_k_bones(D, 9, index, distance);
  EXPECT_EQ(index.cols(), 4) << "K is capped at #B";
}

TEST(BoneWeights, ARootWithAHelperBoneGivesItsWeightToTheNearerOfItsTwoBones) {
  // root(0) → a(1), the root's tip below it (leaf_bones' roots): bones (0,0 root helper), (0,1),
  // (1,1 helper).
  geometry::Skeleton s;
  s.names = {"root", "a"};
  s.parents = {-1, 0};
  s.positions.resize(2, 3);
  s.positions << 0, 1, 0, 0, 2, 0;
  s.leaf_tips = s.positions;
  s.leaf_tips.row(0) << 0, 0, 0;
  s.leaf_tips.row(1) << 0, 3, 0;
  ASSERT_TRUE(s.has_root_bone());
  geometry::SparseWeights W(2, 2);
  W.insert(0, 0) = 1.0;  // below the root
  W.insert(1, 0) = 0.7;  // beside the root's bone to a
  W.insert(1, 1) = 0.3;
  Eigen::MatrixXd D(2, 3);
  D << 0.1, 0.5, 1.5,
       0.6, 0.2, 0.8;
  const Eigen::MatrixXd B = data::bone_weights(W, s, D);
  Eigen::MatrixXd expected(2, 3);
  expected << 1.0, 0, 0, 0, 0.7, 0.3;
  EXPECT_TRUE(B.isApprox(expected)) << B;
}

TEST(PreprocessLeaves, DroppedWeightlessEndJointsTakeTheirClipTransformsWithThem) {
  // OpenDungeons' Knight (bundled, with clips) with an extra weightless end joint under its first
  // leaf, in every clip too.
  std::vector<datasets::Excluded> excluded;
  const auto builder = dataset_registry().create(
      config::Config::parse("type: ogre\nlicence: CC0-1.0\npath: " SKINLAB_SOURCE_DIR
                            "/datasets/ogre/bundled/opendungeons\n")
          .root());
  const auto knights = builder->read(excluded);
  ASSERT_EQ(knights.size(), 1u);
  const datasets::SourceCharacter& plain = knights[0];
  ASSERT_FALSE(plain.animations.empty());
  datasets::SourceCharacter extra = plain;
  auto& sk = extra.character.skeleton;
  const auto kids = sk.children();
  int leaf = 0;
  while (!kids[static_cast<std::size_t>(leaf)].empty()) ++leaf;
  sk.names.push_back("extra_end");
  sk.parents.push_back(leaf);
  sk.positions.conservativeResize(sk.num_joints(), 3);
  sk.positions.row(sk.num_joints() - 1) = sk.positions.row(leaf);
  extra.character.weights.conservativeResize(extra.character.weights.rows(), sk.num_joints());
  ASSERT_EQ(extra.bind.size(), static_cast<std::size_t>(sk.num_joints() - 1));
  extra.bind.push_back(extra.bind[static_cast<std::size_t>(leaf)]);
  for (auto& a : extra.animations) {
    a.bind.push_back(a.bind[static_cast<std::size_t>(leaf)]);
    for (auto& frame : a.frames) frame.push_back(frame[static_cast<std::size_t>(leaf)]);
  }
  data::PreprocessOptions drop;
  drop.drop_weightless_leaves = 1.0;
  drop.leaf_bones.kind = distances::LeafBoneOptions::Kind::kExtended;
  const auto a = data::preprocess(extra, euclidean(), drop);
  data::PreprocessOptions keep = drop;
  keep.drop_weightless_leaves = 0.0;
  const auto b = data::preprocess(plain, euclidean(), keep);
  // The extra joint is gone again (and so is any weightless end joint the player has).
  EXPECT_LE(a.num_joints(), b.num_joints());
  EXPECT_EQ(std::count(a.joint_names.begin(), a.joint_names.end(), "extra_end"), 0);
  ASSERT_EQ(a.animations.size(), b.animations.size());
  for (std::size_t i = 0; i < a.animations.size(); ++i) {
    EXPECT_EQ(a.animations[i].bind.size(), static_cast<std::size_t>(12 * a.num_joints()));
  }
  // The character's own bind pose follows the kept joints too, and equals its clips'.
  EXPECT_EQ(a.bind, a.animations.front().bind);
  EXPECT_EQ(b.bind, b.animations.front().bind);
  // Extended leaf bones: tips for every joint, some leaf reaching beyond its joint.
  ASSERT_EQ(a.leaf_tips.rows(), a.num_joints());
  EXPECT_GT((a.leaf_tips - a.joints).rowwise().norm().maxCoeff(), 0.01);
  EXPECT_EQ(data::preprocess(plain, euclidean()).leaf_tips.size(), 0);  // the paper's default
}

// `right_handed` mirrors a left-handed character (0 A.D.'s game frame) front to back before
// everything else, so the prepared mesh and joints are the mirror image of the left-handed
// preparation (normalisation centres z, so the mirror is about z = 0), with the same distances
// (a mirror keeps them); a right-handed character is prepared as without the option.
TEST(PreprocessFrame, RightHandedMirrorsOnlyLeftHandedCharacters) {
  datasets::SourceCharacter left = testing::minetest_player();
  left.left_handed = true;
  data::PreprocessOptions mirror;
  mirror.right_handed = true;
  const data::PreparedCharacter kept = data::preprocess(left, euclidean());
  const data::PreparedCharacter mirrored = data::preprocess(left, euclidean(), mirror);
  const Eigen::Vector3d flip(1, 1, -1);
  ASSERT_EQ(mirrored.V.rows(), kept.V.rows());
  EXPECT_LT((mirrored.V - kept.V * flip.asDiagonal()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((mirrored.joints - kept.joints * flip.asDiagonal()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(mirrored.F, kept.F);
  ASSERT_EQ(mirrored.distances.size(), kept.distances.size());
  for (const auto& [type, d] : kept.distances) {
    EXPECT_EQ(mirrored.distances.at(type).topk_index, d.topk_index) << type;
  }
  const datasets::SourceCharacter right = testing::minetest_player();
  EXPECT_EQ(data::preprocess(right, euclidean(), mirror).V, data::preprocess(right, euclidean()).V);
  EXPECT_TRUE(data::PreprocessOptions::from(
                  config::Config::parse("preprocess: {right_handed: true}").root()["preprocess"])
                  .right_handed);
}

TEST(PreprocessOptions, UnknownFieldIsAnError) {
  const auto config = config::Config::parse("preprocess: {top_kk: 3}");
  testing::expect_error<ConfigError>(
      [&] { data::PreprocessOptions::from(config.root()["preprocess"]); },
      {"top_kk", "did you mean 'top_k'"});
}

TEST(FolderBuilder, ReadsCharactersAndExcludesBadFiles) {
  TempDir dir;
  const auto player = testing::minetest_player();
  std::filesystem::copy_file(std::string(testing::kMinetestModels) + "/character.b3d",
                             dir / "player.b3d");
  std::filesystem::create_directories(dir / "sub");
  geometry::write_obj(dir / "sub/hero.obj", player.character.mesh);
  geometry::write_rig(dir / "sub/hero_rig.txt", player.character.skeleton,
                      player.character.weights);
  dir.write("broken.fbx", "this is not an FBX file");
  dir.write("lonely.obj", "v 0 0 0\n");
  dir.write("notes.txt", "ignored");

  std::vector<datasets::Excluded> excluded;
  auto flat = testing::folder_builder(dir.path().string())->read(excluded);
  ASSERT_EQ(flat.size(), 1u);
  EXPECT_EQ(flat[0].character.name, "player");
  EXPECT_EQ(flat[0].skeleton, "player") << "default family: the file's stem";
  ASSERT_EQ(excluded.size(), 2u);
  EXPECT_EQ(excluded[0].path, "broken.fbx");
  EXPECT_NE(excluded[0].reason.find("broken.fbx"), std::string::npos) << excluded[0].reason;
  EXPECT_EQ(excluded[1].path, "lonely.obj");
  EXPECT_NE(excluded[1].reason.find("lonely_rig.txt"), std::string::npos) << excluded[1].reason;

  excluded.clear();
  auto all = testing::folder_builder(dir.path().string(), "recursive: true\nskeleton: human\n")
                 ->read(excluded);
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[1].character.name, "sub.hero");
  EXPECT_EQ(all[1].path, "sub/hero.obj");
  EXPECT_EQ(all[1].skeleton, "human");
  EXPECT_EQ(all[1].character.mesh.V, player.character.mesh.V);
  EXPECT_EQ(excluded.size(), 2u);

  testing::expect_error<IoError>(
      [&] { testing::folder_builder((dir / "missing").string())->read(excluded); },
      {"missing", "not a readable directory"});
  testing::expect_error<ConfigError>(
      [&] { dataset_registry().create(config::Config::parse("type: folder").root()); }, {"path"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

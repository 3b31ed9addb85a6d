// The IQM reader and the `cube2` builder on the bundled Sauerbraten character snoutx10k
// (cube2-data, CC-BY-3.0; datasets/cube2/bundled/LICENSE.md).

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "datasets/byte_reader.hpp"
#include "datasets/cube2/cube2.hpp"
#include "datasets/cube2/iqm.hpp"
#include "framework/core/registry.hpp"
#include "framework/geometry/lbs.hpp"
#include "tests/test_util.hpp"

namespace skinlab::datasets {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

const std::string kBundled = SKINLAB_SOURCE_DIR "/datasets/cube2/bundled";
const std::string kModel = kBundled + "/snoutx10k/snoutx10k.iqm";
const std::string kAnim = kBundled + "/snoutx10k/forward.md5anim.iqm";

std::vector<Eigen::Affine3d> skinning_transforms(const Transforms& frame, const Transforms& bind) {
  std::vector<Eigen::Affine3d> T(frame.size());
  for (std::size_t j = 0; j < frame.size(); ++j)
    T[j] = Eigen::Affine3d((frame[j] * bind[j].inverse()).matrix());
  return T;
}

TEST(Iqm, ReadsSnoutCountsNamesAndWeights) {
  const cube2::IqmFile iqm = cube2::read_iqm_file(kModel);
  EXPECT_EQ(iqm.mesh_names, (std::vector<std::string>{"Lower", "Upper"}));
  EXPECT_EQ(iqm.model.V.rows(), 2451);
  EXPECT_EQ(iqm.model.F.rows(), 3520);
  ASSERT_EQ(iqm.model.joint_names.size(), 75u);
  EXPECT_EQ(iqm.model.joint_names[0], "Root");
  EXPECT_EQ(iqm.model.joint_names[73], "ElbowRot.L");
  EXPECT_EQ(iqm.model.parents[0], -1);
  EXPECT_EQ(iqm.model.parents[3], 2);  // SpineIK1 under Torso
  ASSERT_TRUE(iqm.has_blend_weights);
  EXPECT_EQ(iqm.model.W.rows(), 2451);
  EXPECT_EQ(iqm.model.W.cols(), 75);
  for (int v = 0; v < iqm.model.W.rows(); ++v) {
    ASSERT_NEAR(iqm.model.W.row(v).sum(), 1.0, 1e-12) << "vertex " << v;
  }
  EXPECT_TRUE(iqm.clips.empty());
  EXPECT_TRUE(iqm.pose_parents.empty());
}

TEST(Iqm, ReadsAnimationFile) {
  const cube2::IqmFile anim = cube2::read_iqm_file(kAnim);
  EXPECT_FALSE(anim.has_geometry());
  ASSERT_EQ(anim.clips.size(), 1u);
  EXPECT_EQ(anim.clips[0].name, "forward");
  EXPECT_DOUBLE_EQ(anim.clips[0].fps, 24.0);
  EXPECT_GT(anim.clips[0].local.size(), 1u);
  EXPECT_EQ(anim.pose_parents, cube2::read_iqm_file(kModel).model.parents);
}

Cube2Builder::Options bundled_options() {
  Cube2Builder::Options o;
  o.path = kBundled;
  o.copyright = kBundled + "/copyright";
  return o;
}

TEST(Cube2, BuilderReadsBundledCharacter) {
  std::vector<Excluded> excluded;
  const auto characters = Cube2Builder(bundled_options()).read(excluded);
  EXPECT_TRUE(excluded.empty()) << excluded.front().path << ": " << excluded.front().reason;
  ASSERT_EQ(characters.size(), 1u);
  const SourceCharacter& sc = characters[0];
  EXPECT_EQ(sc.source, "cube2");
  EXPECT_EQ(sc.path, "snoutx10k/snoutx10k.iqm");
  EXPECT_EQ(sc.skeleton, "snoutx10k");
  EXPECT_EQ(sc.licence, "CC-BY-3.0");
  EXPECT_NE(sc.attribution.find("geartrooper"), std::string::npos) << sc.attribution;
  geometry::Character c = sc.character;
  EXPECT_EQ(c.name, "snoutx10k.snoutx10k");
  EXPECT_EQ(sc.up, Eigen::Vector3d::UnitZ());
  EXPECT_NO_THROW(c.validate());
  // The two unweighted IK roots ElbowRot.L/.R are pruned; the tree under Root stays whole.
  EXPECT_EQ(c.skeleton.num_joints(), 73);
  EXPECT_EQ(c.skeleton.find("ElbowRot.L"), -1);
  EXPECT_EQ(c.skeleton.names[c.skeleton.root()], "Root");
  EXPECT_EQ(c.mesh.num_vertices(), 2451);
  EXPECT_EQ(c.mesh.num_faces(), 3520);
  // Skinned joints lie inside the mesh's bounding box (a wrong composition flings them away).
  const Eigen::RowVector3d lo = c.mesh.V.colwise().minCoeff(), hi = c.mesh.V.colwise().maxCoeff();
  const double pad = 0.1 * (hi - lo).norm();
  std::vector<double> joint_weight(c.skeleton.num_joints(), 0.0);
  for (int v = 0; v < c.weights.outerSize(); ++v) {
    for (geometry::SparseWeights::InnerIterator it(c.weights, v); it; ++it)
      joint_weight[it.col()] += it.value();
  }
  for (int j = 0; j < c.skeleton.num_joints(); ++j) {
    if (joint_weight[j] == 0) continue;
    const Eigen::RowVector3d p = c.skeleton.positions.row(j);
    EXPECT_TRUE(((p.array() >= lo.array() - pad) && (p.array() <= hi.array() + pad)).all())
        << c.skeleton.names[j] << " at " << p;
  }
  ASSERT_EQ(sc.animations.size(), 1u);
  EXPECT_EQ(sc.animations[0].name, "forward");
  EXPECT_EQ(sc.animations[0].bind.size(), 73u);
}

TEST(Cube2, LbsWithBindPoseReproducesMeshAndAFrameMovesItPlausibly) {
  std::vector<Excluded> excluded;
  const auto characters = Cube2Builder(bundled_options()).read(excluded);
  ASSERT_EQ(characters.size(), 1u);
  const geometry::Character& c = characters[0].character;
  const Animation& a = characters[0].animations.at(0);
  for (std::size_t j = 0; j < a.bind.size(); ++j) {
    EXPECT_TRUE(a.bind[j].translation().isApprox(c.skeleton.positions.row(j).transpose()));
  }
  const Eigen::MatrixXd rest =
      geometry::lbs(c.mesh.V, c.weights, skinning_transforms(a.bind, a.bind));
  EXPECT_LT((rest - c.mesh.V).cwiseAbs().maxCoeff(), 1e-9);

  const double height = (c.mesh.V.colwise().maxCoeff() - c.mesh.V.colwise().minCoeff()).norm();
  const Eigen::MatrixXd posed = geometry::lbs(
      c.mesh.V, c.weights, skinning_transforms(a.frames[a.frames.size() / 2], a.bind));
  ASSERT_TRUE(posed.allFinite());
  const double moved = (posed - c.mesh.V).rowwise().norm().maxCoeff();
  EXPECT_GT(moved, 0.02 * height);  // a running frame is not the bind pose
  EXPECT_LT(moved, 1.5 * height);   // but the character stays in one piece near its place
  const double posed_size = (posed.colwise().maxCoeff() - posed.colwise().minCoeff()).norm();
  EXPECT_NEAR(posed_size / height, 1.0, 0.3);
  // Skinning moves nearby vertices almost rigidly: edge lengths barely change.
  std::vector<double> ratio;
  for (int f = 0; f < c.mesh.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int u = c.mesh.F(f, k), v = c.mesh.F(f, (k + 1) % 3);
      const double before = (c.mesh.V.row(u) - c.mesh.V.row(v)).norm();
      if (before > 1e-6 * height) ratio.push_back((posed.row(u) - posed.row(v)).norm() / before);
    }
  }
  std::nth_element(ratio.begin(), ratio.begin() + ratio.size() / 2, ratio.end());
  EXPECT_NEAR(ratio[ratio.size() / 2], 1.0, 0.02);
}

TEST(Iqm, TruncatedFileNamesFileAndOffset) {
  const std::string bytes = read_binary_file(kModel);
  testing::expect_error<IoError>([&] { cube2::read_iqm(bytes.substr(0, 100000), "snout.iqm"); },
                                 {"snout.iqm", "byte offset 0", "needs 226560 bytes", "100000"});
  testing::expect_error<IoError>([&] { cube2::read_iqm(bytes.substr(0, 60), "snout.iqm"); },
                                 {"snout.iqm", "header", "byte offset 0", "needs 124 bytes"});
}

TEST(Iqm, CorruptElementsAreNamed) {
  std::string bytes = read_binary_file(kModel);
  // Triangle 5's second index points past the vertices.
  const std::uint32_t ofs_triangles =
      ByteReader(bytes, "", ByteReader::Endian::kLittle).u32(16 + 4 * 11, "");
  const std::uint32_t huge = 999999;
  std::memcpy(&bytes[ofs_triangles + 12 * 5 + 4], &huge, 4);
  testing::expect_error<IoError>(
      [&] { cube2::read_iqm(bytes, "snout.iqm"); },
      {"snout.iqm: triangle 5 (byte offset " + std::to_string(ofs_triangles + 60) + ")",
       "vertex index 999999"});
  std::string wrong = read_binary_file(kModel);
  wrong[0] = 'X';
  testing::expect_error<IoError>([&] { cube2::read_iqm(wrong, "snout.iqm"); }, {"not an IQM file"});
}

TEST(Cube2, RegisteredWithOptions) {
  const auto config = config::Config::parse("{type: cube2, path: /nonexistent/models}", "d.yaml");
  const auto builder = dataset_registry().create(config.root());
  std::vector<Excluded> excluded;
  testing::expect_error<IoError>([&] { builder->read(excluded); },
                                 {"/nonexistent/models", "not a directory"});
  const auto typo = config::Config::parse("{type: cube2, pth: x}", "d.yaml");
  testing::expect_error<ConfigError>([&] { dataset_registry().create(typo.root()); }, {"pth"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::datasets

// The ZYM and zip readers and the `nexuiz` builder on the bundled Nexuiz player "marine"
// (nexuiz-data, GPL-2+; datasets/nexuiz/bundled/LICENSE.md).

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "datasets/byte_reader.hpp"
#include "datasets/nexuiz/nexuiz.hpp"
#include "datasets/nexuiz/pk3.hpp"
#include "datasets/nexuiz/zym.hpp"
#include "framework/core/registry.hpp"
#include "framework/geometry/lbs.hpp"
#include "tests/datasets/zip_writer.hpp"
#include "tests/test_util.hpp"

namespace skinlab::datasets {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

const std::string kBundled = SKINLAB_SOURCE_DIR "/datasets/nexuiz/bundled";
const std::string kModel = kBundled + "/models/player/marine.zym";

std::vector<Eigen::Affine3d> skinning_transforms(const Transforms& frame, const Transforms& bind) {
  std::vector<Eigen::Affine3d> T(frame.size());
  for (std::size_t j = 0; j < frame.size(); ++j)
    T[j] = Eigen::Affine3d((frame[j] * bind[j].inverse()).matrix());
  return T;
}

using testing::make_zip;

TEST(Zym, ReadsMarineCountsNamesAndRigidWeights) {
  const nexuiz::ZymFile zym = nexuiz::read_zym_file(kModel);
  EXPECT_EQ(zym.model.V.rows(), 2168);
  EXPECT_EQ(zym.model.F.rows(), 3028);
  EXPECT_EQ(zym.model.joint_names.size(), 38u);
  EXPECT_EQ(zym.shader_names.size(), 1u);
  ASSERT_EQ(zym.scenes.size(), 23u);
  EXPECT_EQ(zym.poses.size(), 390u);
  EXPECT_GT(zym.scenes[0].fps, 0);
  for (int v = 0; v < zym.model.W.rows(); ++v) {
    ASSERT_EQ(zym.model.W.row(v).nonZeros(), 1) << "vertex " << v;
    ASSERT_DOUBLE_EQ(zym.model.W.row(v).sum(), 1.0);
  }
  // The mesh is placed with pose 0: a standing character, taller than wide (Z up).
  const Eigen::RowVector3d extent =
      zym.model.V.colwise().maxCoeff() - zym.model.V.colwise().minCoeff();
  EXPECT_GT(extent.z(), extent.x());
  EXPECT_GT(extent.z(), extent.y());
}

nexuiz::ZymFile marine() { return nexuiz::read_zym_file(kModel); }

NexuizBuilder::Options bundled_options(const std::string& path = kBundled) {
  NexuizBuilder::Options o;
  o.path = path;
  o.copyright = kBundled + "/copyright";
  return o;
}

TEST(Nexuiz, BuilderReadsBundledDirectory) {
  std::vector<Excluded> excluded;
  const auto characters = NexuizBuilder(bundled_options()).read(excluded);
  EXPECT_TRUE(excluded.empty());
  ASSERT_EQ(characters.size(), 1u);
  const SourceCharacter& sc = characters[0];
  EXPECT_EQ(sc.source, "nexuiz");
  EXPECT_EQ(sc.path, "models/player/marine.zym");
  EXPECT_EQ(sc.skeleton, "marine");
  EXPECT_EQ(sc.licence, "GPL-2.0-or-later");
  EXPECT_NE(sc.attribution.find("Alientrap"), std::string::npos) << sc.attribution;
  geometry::Character c = sc.character;
  EXPECT_EQ(c.name, "player.marine");
  EXPECT_EQ(sc.up, Eigen::Vector3d::UnitZ());
  EXPECT_NO_THROW(c.validate());
  EXPECT_EQ(c.mesh.num_vertices(), 2168);
  // Unweighted extra roots (4 roots in the file) are pruned to one tree.
  EXPECT_LT(c.skeleton.num_joints(), 38);
  EXPECT_GE(c.skeleton.num_joints(), 24);  // the 24 bones that skin vertices and their ancestors
  EXPECT_EQ(sc.animations.size(), 23u);
  for (const auto& a : sc.animations) {
    EXPECT_FALSE(a.name.empty());
    EXPECT_EQ(a.bind.size(), static_cast<std::size_t>(c.skeleton.num_joints()));
    for (const auto& frame : a.frames) ASSERT_EQ(frame.size(), a.bind.size());
  }
}

TEST(Nexuiz, LbsWithBindPoseReproducesMeshAndFramesMoveItRigidly) {
  std::vector<Excluded> excluded;
  const auto characters = NexuizBuilder(bundled_options()).read(excluded);
  ASSERT_EQ(characters.size(), 1u);
  const geometry::Character& c = characters[0].character;
  const Animation& first = characters[0].animations.at(0);
  // Pose 0 is the bind pose: the first frame of the first scene reproduces the mesh.
  const Eigen::MatrixXd rest =
      geometry::lbs(c.mesh.V, c.weights, skinning_transforms(first.frames[0], first.bind));
  EXPECT_LT((rest - c.mesh.V).cwiseAbs().maxCoeff(), 1e-4);
  // The mesh rebuilt from the file's bone-space origins equals the character's mesh.
  EXPECT_LT((marine().model.V - c.mesh.V).cwiseAbs().maxCoeff(), 1e-12);

  const double height = (c.mesh.V.colwise().maxCoeff() - c.mesh.V.colwise().minCoeff()).norm();
  double most = 0;
  std::vector<int> bone(c.mesh.num_vertices());
  for (int v = 0; v < c.weights.outerSize(); ++v)
    bone[v] = geometry::SparseWeights::InnerIterator(c.weights, v).col();
  for (const auto& a : characters[0].animations) {
    const Eigen::MatrixXd posed =
        geometry::lbs(c.mesh.V, c.weights, skinning_transforms(a.frames.back(), a.bind));
    ASSERT_TRUE(posed.allFinite()) << a.name;
    most = std::max(most, (posed - c.mesh.V).rowwise().norm().maxCoeff());
    const double size = (posed.colwise().maxCoeff() - posed.colwise().minCoeff()).norm();
    EXPECT_GT(size, 0.5 * height) << a.name;
    EXPECT_LT(size, 2.0 * height) << a.name;
    // Rigid skinning: an edge between vertices of one bone keeps its length exactly.
    for (int f = 0; f < c.mesh.num_faces(); ++f) {
      const int u = c.mesh.F(f, 0), v = c.mesh.F(f, 1);
      if (bone[u] != bone[v]) continue;
      ASSERT_NEAR((posed.row(u) - posed.row(v)).norm(), (c.mesh.V.row(u) - c.mesh.V.row(v)).norm(),
                  1e-3 * height)
          << a.name << " face " << f;
    }
  }
  EXPECT_GT(most, 0.05 * height);  // some scene really moves the character
}

TEST(Zym, TruncatedAndCorruptFilesNameFileAndOffset) {
  const std::string bytes = read_binary_file(kModel);
  testing::expect_error<IoError>([&] { nexuiz::read_zym(bytes.substr(0, 5000), "marine.zym"); },
                                 {"marine.zym", "byte offset 0", "needs 814872 bytes", "5000"});
  testing::expect_error<IoError>([&] { nexuiz::read_zym(bytes.substr(0, 100), "marine.zym"); },
                                 {"marine.zym: header (byte offset 0): needs 140 bytes"});
  // Vertex 7 points at a bone that does not exist.
  std::string bad = bytes;
  const ByteReader r(bytes, "", ByteReader::Endian::kBig);
  const std::size_t verts = r.u32(68 + 8 * 4, "");
  bad[verts + 16 * 7] = 0x7f;
  testing::expect_error<IoError>(
      [&] { nexuiz::read_zym(bad, "marine.zym"); },
      {"marine.zym: vertex 7 (byte offset " + std::to_string(verts + 112) + ")", "bone"});
  testing::expect_error<IoError>([&] { nexuiz::read_zym("IDP3" + bytes.substr(4), "m.zym"); },
                                 {"not a ZYM file"});
}

TEST(Pk3, ReadsDeflatedAndStoredMembersAndFeedsTheBuilder) {
  testing::TempDir dir;
  const std::string zym = read_binary_file(kModel);
  const auto file =
      dir.write("data.pk3", make_zip({{"models/player/marine.zym", zym, true},
                                      {"models/weapons/w_x.zym", "ZYMOTIC", false},
                                      {"models/player/broken.zym", zym.substr(0, 9000), true},
                                      {"readme.txt", "hello", false}}));
  const nexuiz::ZipArchive archive(file);
  ASSERT_EQ(archive.entries().size(), 4u);
  EXPECT_EQ(archive.read(*archive.find("models/player/marine.zym")), zym);
  EXPECT_EQ(archive.read(*archive.find("readme.txt")), "hello");
  EXPECT_EQ(archive.find("nothing"), nullptr);

  std::vector<Excluded> excluded;
  const auto characters = NexuizBuilder(bundled_options(file.string())).read(excluded);
  ASSERT_EQ(characters.size(), 1u);
  EXPECT_EQ(characters[0].character.name, "player.marine");
  ASSERT_EQ(excluded.size(), 2u);
  EXPECT_EQ(excluded[0].path, "models/player/broken.zym");
  EXPECT_NE(excluded[0].reason.find("data.pk3:models/player/broken.zym"), std::string::npos)
      << excluded[0].reason;
  EXPECT_NE(excluded[0].reason.find("byte offset"), std::string::npos) << excluded[0].reason;
  EXPECT_EQ(excluded[1].path, "models/weapons/w_x.zym");
  EXPECT_NE(excluded[1].reason.find("not a player character"), std::string::npos);
}

TEST(Pk3, TruncatedOrCorruptArchivesAreErrors) {
  testing::TempDir dir;
  const std::string zip = make_zip({{"a.zym", std::string(5000, 'x'), true}});
  const auto cut = dir.write("cut.pk3", zip.substr(0, zip.size() - 30));
  testing::expect_error<IoError>([&] { nexuiz::ZipArchive a(cut); },
                                 {"cut.pk3", "not a zip archive"});
  std::string flipped = zip;
  flipped[40] ^= 0x55;  // inside the deflated data of the only member
  const auto bad = dir.write("bad.pk3", flipped);
  const nexuiz::ZipArchive archive(bad);
  testing::expect_error<IoError>([&] { archive.read(archive.entries()[0]); }, {"bad.pk3:a.zym"});
  const auto foreign = dir.write("foreign.pk3", std::string(100, 'q'));
  testing::expect_error<IoError>([&] { nexuiz::ZipArchive a(foreign); },
                                 {"foreign.pk3", "not a zip"});
}

TEST(RiggedModel, PrunesUnusableHelperSubtreesButNotWeightedOnes) {
  // Root, hand (skins the triangle) and a weapon tag under the hand with a degenerate matrix.
  RiggedModel m;
  m.name = "toy";
  m.joint_names = {"root", "hand", "tag", "tag_child"};
  m.parents = {-1, 0, 1, 2};
  m.bind.assign(4, Eigen::Isometry3d::Identity());
  m.V = Eigen::MatrixXd::Identity(3, 3);
  m.F = Eigen::MatrixXi(1, 3);
  m.F << 0, 1, 2;
  m.W.resize(3, 4);
  for (int v = 0; v < 3; ++v) m.W.insert(v, 1) = 1.0;
  m.unusable = {false, false, true, false};
  const SourceRig rig = to_source_rig(m);
  EXPECT_EQ(rig.character.skeleton.names, (std::vector<std::string>{"root", "hand"}));
  EXPECT_EQ(rig.kept, (std::vector<int>{0, 1}));
  m.W.coeffRef(2, 1) = 0.5;
  m.W.insert(2, 3) = 0.5;  // now the unusable tag's subtree skins vertex 2
  testing::expect_error<geometry::GeometryError>([&] { to_source_rig(m); },
                                                 {"toy", "joint 2 'tag'", "degenerate"});
}

TEST(Nexuiz, RegisteredWithOptions) {
  const auto config =
      config::Config::parse("{type: nexuiz, path: /nonexistent/data.pk3, lods: true}", "d.yaml");
  const auto builder = dataset_registry().create(config.root());
  std::vector<Excluded> excluded;
  testing::expect_error<IoError>([&] { builder->read(excluded); }, {"/nonexistent/data.pk3"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::datasets

// The OGRE .mesh/.skeleton reader and the `ogre` builder on two bundled real characters
// (datasets/ogre/bundled/LICENSE.md): OpenDungeons' Knight (CC0, mesh v1.100, skeleton v1.80)
// and Summoning Wars' fire slug (CC-BY-SA-3.0, mesh v1.41 with a short sub-mesh chunk length,
// skeleton v1.10).

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "datasets/byte_reader.hpp"
#include "datasets/ogre/ogre.hpp"
#include "datasets/ogre/ogre_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/geometry/lbs.hpp"
#include "tests/test_util.hpp"

namespace skinlab::datasets {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;

const std::string kBundled = SKINLAB_SOURCE_DIR "/datasets/ogre/bundled";
const std::string kKnightMesh = kBundled + "/opendungeons/Knight.mesh";
const std::string kKnightSkeleton = kBundled + "/opendungeons/Knight.skeleton";
const std::string kSlugMesh = kBundled + "/sumwars/fire_slug.mesh";
const std::string kSlugSkeleton = kBundled + "/sumwars/fire_slug.skeleton";

void write_file(const fs::path& file, const std::string& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary) << bytes;
}

OgreBuilder::Options options_for(const std::string& path) {
  OgreBuilder::Options o;
  o.source.path = path;
  o.licence = "CC0-1.0";
  return o;
}

std::vector<SourceCharacter> build(const OgreBuilder::Options& o, std::vector<Excluded>& excluded) {
  return OgreBuilder(o).read(excluded);
}

TEST(OgreFile, ReadsKnightMeshV1100) {
  const ogre::OgreMesh m = ogre::parse_mesh(read_binary_file(kKnightMesh), "Knight.mesh");
  EXPECT_EQ(m.version, "[MeshSerializer_v1.100]");
  EXPECT_EQ(m.skeleton_link, "Knight.skeleton");
  EXPECT_EQ(m.num_submeshes, 2);
  EXPECT_EQ(m.V.rows(), 370);
  EXPECT_EQ(m.F.rows() + m.num_dropped_degenerate, 422);
  EXPECT_EQ(m.assignments.size(), 639u);
  EXPECT_EQ(m.F.maxCoeff(), 369);
}

TEST(OgreFile, ReadsSlugMeshV141WithShortSubMeshLength) {
  // The sub-mesh chunk's stored length ends 6 bytes before its last bone assignment: read
  // sequentially as OGRE does, every assignment is found.
  const ogre::OgreMesh m = ogre::parse_mesh(read_binary_file(kSlugMesh), "fire_slug.mesh");
  EXPECT_EQ(m.version, "[MeshSerializer_v1.41]");
  EXPECT_EQ(m.skeleton_link, "fire_slug.skeleton");
  EXPECT_EQ(m.V.rows(), 184);
  EXPECT_EQ(m.F.rows() + m.num_dropped_degenerate, 240);
  EXPECT_EQ(m.assignments.size(), 374u);
}

TEST(OgreFile, ReadsSkeletonsAndBindPose) {
  const ogre::OgreSkeleton k = ogre::parse_skeleton(read_binary_file(kKnightSkeleton), "Knight.skeleton");
  EXPECT_EQ(k.version, "[Serializer_v1.80]");
  ASSERT_EQ(k.bones.size(), 32u);
  EXPECT_EQ(k.animations.size(), 6u);
  int roots = 0;
  for (const auto& b : k.bones) roots += b.parent < 0;
  EXPECT_EQ(roots, 1);
  const ogre::OgreSkeleton s = ogre::parse_skeleton(read_binary_file(kSlugSkeleton), "fire_slug.skeleton");
  EXPECT_EQ(s.version, "[Serializer_v1.10]");
  EXPECT_EQ(s.bones.size(), 22u);
  EXPECT_EQ(s.animations.size(), 6u);
  // The derived bind pose of a child is its parent's transform applied to its local offset.
  const ogre::BindPose bind = ogre::derive_bind_pose(k);
  for (std::size_t b = 0; b < k.bones.size(); ++b) {
    const int p = k.bones[b].parent;
    if (p < 0) continue;
    const Eigen::Vector3d expected = bind.orientation[p] * k.bones[b].position + bind.position[p];
    EXPECT_LT((bind.position[b] - expected).norm(), 1e-9) << k.bones[b].name;
  }
  // At time 0 a clip whose first keys are the identity reproduces the bind pose.
  const ogre::BindPose start = ogre::sample_animation(k, k.animations[0], 0.0);
  ASSERT_EQ(start.position.size(), k.bones.size());
  for (const auto& p : start.position) EXPECT_TRUE(p.allFinite());
}

TEST(Ogre, BuilderReadsBundledCharacters) {
  std::vector<Excluded> excluded;
  OgreBuilder::Options o = options_for(kBundled);
  o.credits.push_back({"Knight.*", "CC0-1.0", "surt"});
  o.credits.push_back({"sumwars/*", "CC-BY-SA-3.0", "Summoning Wars team"});
  const auto characters = build(o, excluded);
  EXPECT_TRUE(excluded.empty()) << excluded.front().path << ": " << excluded.front().reason;
  ASSERT_EQ(characters.size(), 2u);

  const SourceCharacter& knight = characters[0];
  EXPECT_EQ(knight.source, "ogre");
  EXPECT_EQ(knight.path, "opendungeons/Knight.mesh");
  EXPECT_EQ(knight.character.name, "opendungeons.Knight");
  EXPECT_EQ(knight.skeleton, "Knight");
  EXPECT_EQ(knight.licence, "CC0-1.0");
  EXPECT_EQ(knight.attribution, "surt");
  EXPECT_EQ(knight.character.skeleton.num_joints(), 32);
  EXPECT_EQ(knight.character.mesh.V.rows(), 370);
  EXPECT_EQ(knight.up, Eigen::Vector3d::UnitY());  // the default

  const SourceCharacter& slug = characters[1];
  EXPECT_EQ(slug.character.name, "sumwars.fire_slug");
  EXPECT_EQ(slug.skeleton, "fire_slug");
  EXPECT_EQ(slug.licence, "CC-BY-SA-3.0");
  EXPECT_EQ(slug.character.skeleton.num_joints(), 22);
  EXPECT_EQ(slug.character.mesh.V.rows(), 184);

  for (const SourceCharacter& sc : characters) {
    const geometry::Character& c = sc.character;
    ASSERT_EQ(c.weights.rows(), c.mesh.V.rows());
    for (int v = 0; v < c.weights.rows(); ++v) {
      ASSERT_NEAR(c.weights.row(v).sum(), 1.0, 1e-12) << sc.path << " vertex " << v;
      ASSERT_LE(c.weights.row(v).nonZeros(), 4) << sc.path << " vertex " << v;
    }
    // The skeleton lies in the mesh's frame: the joints' box overlaps the mesh's box.
    const Eigen::RowVector3d lo = c.mesh.V.colwise().minCoeff(), hi = c.mesh.V.colwise().maxCoeff();
    const Eigen::RowVector3d centre = c.skeleton.positions.colwise().mean();
    EXPECT_TRUE((centre.array() >= lo.array() - 0.1 * (hi - lo).norm()).all() &&
                (centre.array() <= hi.array() + 0.1 * (hi - lo).norm()).all())
        << sc.path;
  }
}

TEST(Ogre, AnimationsPoseTheCharacterInOnePiece) {
  std::vector<Excluded> excluded;
  OgreBuilder::Options o = options_for(kBundled);
  o.max_animations_per_character = 2;
  const auto characters = build(o, excluded);
  ASSERT_EQ(characters.size(), 2u);
  for (const SourceCharacter& sc : characters) {
    const geometry::Character& c = sc.character;
    ASSERT_EQ(sc.animations.size(), 2u) << sc.path;
    // The character's own bind pose (kept with or without clips) is its clips' bind.
    ASSERT_EQ(sc.bind.size(), static_cast<std::size_t>(c.skeleton.num_joints())) << sc.path;
    for (std::size_t j = 0; j < sc.bind.size(); ++j) {
      EXPECT_TRUE(sc.bind[j].isApprox(sc.animations.front().bind[j], 0.0)) << sc.path << " " << j;
    }
    for (const Animation& a : sc.animations) {
      EXPECT_DOUBLE_EQ(a.fps, 24.0);
      ASSERT_GT(a.frames.size(), 1u) << sc.path << " " << a.name;
      ASSERT_EQ(a.bind.size(), static_cast<std::size_t>(c.skeleton.num_joints()));
      for (int j = 0; j < c.skeleton.num_joints(); ++j) {
        EXPECT_LT((a.bind[j].translation().transpose() - c.skeleton.positions.row(j)).norm(), 1e-9);
      }
      const double height = (c.mesh.V.colwise().maxCoeff() - c.mesh.V.colwise().minCoeff()).norm();
      double most_moved = 0;
      for (const auto& frame : a.frames) {
        ASSERT_EQ(frame.size(), a.bind.size());
        std::vector<Eigen::Affine3d> T(a.bind.size());
        for (std::size_t j = 0; j < T.size(); ++j) {
          T[j] = Eigen::Affine3d((frame[j] * a.bind[j].inverse()).matrix());
        }
        const Eigen::MatrixXd posed = geometry::lbs(c.mesh.V, c.weights, T);
        ASSERT_TRUE(posed.allFinite());
        most_moved = std::max(most_moved, (posed - c.mesh.V).rowwise().norm().maxCoeff());
        EXPECT_LT((posed - c.mesh.V).rowwise().norm().maxCoeff(), 1.5 * height) << sc.path << " " << a.name;
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
        EXPECT_NEAR(ratio[ratio.size() / 2], 1.0, 0.05) << sc.path << " " << a.name;
      }
      EXPECT_GT(most_moved, 0.01 * height) << sc.path << " " << a.name << ": the clip does not move";
    }
  }
}

TEST(Ogre, SeveralWeightedRootsGetAnOriginJoint) {
  // Cut Spine_1 (handle 22) from its parent COG_Rot (19): the upper body becomes a second
  // weighted root, as in rigs whose body parts hang from separate roots.
  std::string skeleton = read_binary_file(kKnightSkeleton);
  const std::string chunk("\x00\x30\x0a\x00\x00\x00\x16\x00\x13\x00", 10);
  const std::size_t at = skeleton.find(chunk);
  ASSERT_NE(at, std::string::npos);
  skeleton.erase(at, chunk.size());
  testing::TempDir dir;
  write_file(dir / "Knight.mesh", read_binary_file(kKnightMesh));
  write_file(dir / "Knight.skeleton", skeleton);
  std::vector<Excluded> excluded;
  const auto characters = build(options_for(dir.path().string()), excluded);
  ASSERT_EQ(characters.size(), 1u);
  const geometry::Skeleton& s = characters[0].character.skeleton;
  ASSERT_EQ(s.num_joints(), 33);
  EXPECT_EQ(s.names[0], "ogre_origin");
  EXPECT_EQ(s.parents[0], -1);
  EXPECT_LT(s.positions.row(0).norm(), 1e-12);
  int children_of_origin = 0;
  for (int j = 1; j < s.num_joints(); ++j) {
    EXPECT_GE(s.parents[j], 0) << s.names[j];
    children_of_origin += s.parents[j] == 0;
  }
  EXPECT_EQ(children_of_origin, 2);
  EXPECT_EQ(Eigen::MatrixXd(characters[0].character.weights).col(0).cwiseAbs().sum(), 0.0);

  OgreBuilder::Options o = options_for(dir.path().string());
  o.join_weighted_roots = false;
  excluded.clear();
  EXPECT_TRUE(build(o, excluded).empty());
  ASSERT_EQ(excluded.size(), 1u);
  EXPECT_NE(excluded[0].reason.find("root joints carry weights"), std::string::npos) << excluded[0].reason;
}

TEST(Ogre, SkeletonFoundCaseInsensitivelyAndElsewhere) {
  testing::TempDir dir;
  write_file(dir / "creatures/Knight.mesh", read_binary_file(kKnightMesh));
  write_file(dir / "skeletons/KNIGHT.SKELETON", read_binary_file(kKnightSkeleton));
  write_file(dir / "slug/fire_slug.mesh", read_binary_file(kSlugMesh));
  write_file(dir / "slug/Fire_Slug.skeleton", read_binary_file(kSlugSkeleton));
  std::vector<Excluded> excluded;
  const auto characters = build(options_for(dir.path().string()), excluded);
  EXPECT_TRUE(excluded.empty()) << excluded.front().path << ": " << excluded.front().reason;
  ASSERT_EQ(characters.size(), 2u);
  EXPECT_EQ(characters[0].skeleton, "KNIGHT");
  EXPECT_EQ(characters[1].skeleton, "Fire_Slug");
}

TEST(Ogre, ExcludesStaticMeshesMissingSkeletonsAndConfiguredProps) {
  testing::TempDir dir;
  const std::string mesh = read_binary_file(kKnightMesh);
  write_file(dir / "a/Knight.mesh", mesh);  // no skeleton anywhere
  write_file(dir / "props/Knight.mesh", mesh);
  std::vector<Excluded> excluded;
  OgreBuilder::Options o = options_for(dir.path().string());
  o.exclude.emplace_back("props/*", "a prop");
  EXPECT_TRUE(build(o, excluded).empty());
  ASSERT_EQ(excluded.size(), 2u);
  EXPECT_EQ(excluded[0].path, "a/Knight.mesh");
  EXPECT_NE(excluded[0].reason.find("a/Knight.mesh: its skeleton 'Knight.skeleton' is not next to it"),
            std::string::npos)
      << excluded[0].reason;
  EXPECT_NE(excluded[1].reason.find("a prop"), std::string::npos) << excluded[1].reason;
}

TEST(Ogre, TruncatedFilesAreExcludedWithTheFileNamed) {
  const std::string mesh = read_binary_file(kKnightMesh);
  const std::string skeleton = read_binary_file(kKnightSkeleton);
  // Every 97th cut of the mesh (and a few at chunk boundaries) and every 997th of the skeleton.
  std::vector<std::size_t> mesh_cuts = {0, 1, 2, 10, 30, 31, 37, 38, 40};
  for (std::size_t n = 41; n < mesh.size(); n += 97) mesh_cuts.push_back(n);
  for (std::size_t n : mesh_cuts) {
    testing::TempDir dir;
    write_file(dir / "Knight.mesh", mesh.substr(0, n));
    write_file(dir / "Knight.skeleton", skeleton);
    std::vector<Excluded> excluded;
    const auto characters = build(options_for(dir.path().string()), excluded);
    ASSERT_TRUE(characters.empty()) << "cut at " << n;
    ASSERT_EQ(excluded.size(), 1u) << "cut at " << n;
    EXPECT_EQ(excluded[0].path, "Knight.mesh");
    EXPECT_EQ(excluded[0].reason.rfind("Knight.mesh", 0), 0u) << "cut at " << n << ": " << excluded[0].reason;
  }
  for (std::size_t n = 0; n < skeleton.size(); n += 997) {
    testing::TempDir dir;
    write_file(dir / "Knight.mesh", mesh);
    write_file(dir / "Knight.skeleton", skeleton.substr(0, n));
    std::vector<Excluded> excluded;
    const auto characters = build(options_for(dir.path().string()), excluded);
    // A cut inside the animations can leave a readable skeleton with fewer clips; a cut in the
    // bones cannot.
    if (characters.empty()) {
      ASSERT_EQ(excluded.size(), 1u) << "cut at " << n;
      EXPECT_NE(excluded[0].reason.find("Knight.skeleton"), std::string::npos)
          << "cut at " << n << ": " << excluded[0].reason;
    }
  }
  // The mesh chunk's length is not used (it is read item by item); its first sub-mesh's is.
  testing::expect_error<IoError>(
      [&] { ogre::parse_mesh(mesh.substr(0, 1000), "Knight.mesh"); },
      {"Knight.mesh: mesh: chunk 0x4000 (byte offset 33)", "corrupt chunk length 4435",
       "the file has 1000 bytes"});
  testing::expect_error<IoError>(
      [&] { ogre::parse_skeleton(skeleton.substr(0, 100), "Knight.skeleton"); },
      {"Knight.skeleton: skeleton: chunk 0x2000 (byte offset 76)", "corrupt chunk length"});
  // A count that runs past the end is caught where it is read.
  std::string huge = mesh;
  const std::size_t geometry = huge.find(std::string("\x00\x50", 2));  // first M_GEOMETRY id
  ASSERT_NE(geometry, std::string::npos);
  huge[geometry + 6 + 3] = '\x7f';  // its vertex count's high byte
  testing::expect_error<IoError>([&] { ogre::parse_mesh(huge, "Knight.mesh"); },
                                 {"Knight.mesh: ", "geometry", "byte offset"});
}

TEST(OgreFile, MeshChunkLengthPastTheEndIsRead) {
  // OpenClonk's GraphicsAlchemist.mesh and GraphicsSteampunk.mesh store an M_MESH length one
  // byte past the end of the file; the chunk is read item by item, as OpenClonk's loader does.
  const std::string mesh = read_binary_file(kKnightMesh);
  std::string longer = mesh;
  ASSERT_EQ(longer.substr(26, 2), std::string("\x00\x30", 2));  // M_MESH after the header
  longer[28] = static_cast<char>(longer[28] + 1);  // its length's low byte (24919 → 24920)
  const ogre::OgreMesh a = ogre::parse_mesh(mesh, "Knight.mesh");
  const ogre::OgreMesh b = ogre::parse_mesh(longer, "Knight.mesh");
  EXPECT_EQ(a.V, b.V);
  EXPECT_EQ(a.F, b.F);
  EXPECT_EQ(a.assignments.size(), b.assignments.size());
  // A chunk the reader skips by its length must end inside the file.
  std::string skipped = mesh;
  skipped[26] = '\x00', skipped[27] = '\x70';  // not M_MESH: a top-level chunk to skip
  testing::expect_error<IoError>([&] { ogre::parse_mesh(skipped.substr(0, 1000), "Knight.mesh"); },
                                 {"Knight.mesh: chunk 0x7000 (byte offset 26)", "corrupt chunk length 24919"});
}

TEST(Ogre, CorruptedFilesNeverCrash) {
  const std::string mesh = read_binary_file(kSlugMesh);
  const std::string skeleton = read_binary_file(kSlugSkeleton);
  std::mt19937 rng(7);
  int excluded_count = 0;
  for (int trial = 0; trial < 60; ++trial) {
    std::string m = mesh, s = skeleton;
    std::string& target = trial % 2 == 0 ? m : s;
    for (int k = 0; k < 4; ++k) {
      target[std::uniform_int_distribution<std::size_t>(0, target.size() - 1)(rng)] =
          static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
    }
    testing::TempDir dir;
    write_file(dir / "fire_slug.mesh", m);
    write_file(dir / "fire_slug.skeleton", s);
    std::vector<Excluded> excluded;
    const auto characters = build(options_for(dir.path().string()), excluded);
    ASSERT_EQ(characters.size() + excluded.size(), 1u);
    if (!excluded.empty()) {
      ++excluded_count;
      EXPECT_NE(excluded[0].reason.find("fire_slug."), std::string::npos) << excluded[0].reason;
    }
  }
  EXPECT_GT(excluded_count, 0);
  // A bad header names the file and what it found.
  std::string wrong = mesh;
  wrong[0] = 'X';
  testing::expect_error<IoError>([&] { ogre::parse_mesh(wrong, "fire_slug.mesh"); },
                                 {"fire_slug.mesh: file header", "not an OGRE binary mesh"});
  std::string version = mesh;
  version[2 + 17] = '9';  // "[MeshSerializer_v9.41]"
  testing::expect_error<IoError>([&] { ogre::parse_mesh(version, "fire_slug.mesh"); },
                                 {"fire_slug.mesh", "unsupported version '[MeshSerializer_v9.41]'"});
}

TEST(Ogre, OptionsAndRepositoryFolder) {
  const config::Config cfg = config::Config::parse(
      "type: ogre\nsource: opendungeons\nrepository: OpenDungeons/OpenDungeons\ncommit: c83d4496b361f522a094cc8218199b2da1d4264c\npath: models\n"
      "licence: CC0-1.0\nup: [0, 0, 1]\nexclude: {\"Boulder.mesh\": a trap}\n"
      "credits: [{files: \"Orc.*\", licence: CC-BY-SA-3.0, attribution: Skorpio}]\n");
  const OgreBuilder::Options o = OgreBuilder::Options::from(cfg.root());
  EXPECT_EQ(o.source.repository, "OpenDungeons/OpenDungeons");
  EXPECT_EQ(o.source.label("ogre"), "opendungeons");  // the name splits and the card use
  EXPECT_EQ(o.source.commit, "c83d4496b361f522a094cc8218199b2da1d4264c");
  EXPECT_EQ(o.up, (std::vector<double>{0, 0, 1}));
  ASSERT_EQ(o.exclude.size(), 1u);
  EXPECT_EQ(o.exclude[0].second, "a trap");
  ASSERT_EQ(o.credits.size(), 1u);
  EXPECT_EQ(o.credits[0].attribution, "Skorpio");
  const char* saved = std::getenv("SKINLAB_DATA_DIR");
  const std::string restore = saved ? saved : "";
  const std::filesystem::path data =
      std::filesystem::temp_directory_path() / ("skinlab-ogre-data-" + std::to_string(::getpid()));
  std::filesystem::create_directories(data / "OpenDungeons/OpenDungeons");
  ::setenv("SKINLAB_DATA_DIR", data.c_str(), 1);
  EXPECT_EQ(OgreBuilder(o).root(), data / "OpenDungeons/OpenDungeons/models");
  std::filesystem::remove_all(data);
  testing::expect_error<IoError>([&] { OgreBuilder(o).root(); },
                                 {"dataset 'ogre'", "OpenDungeons/OpenDungeons", "fetch_data"});
  ::unsetenv("SKINLAB_DATA_DIR");
  testing::expect_error<IoError>([&] { OgreBuilder(o).root(); }, {"SKINLAB_DATA_DIR"});
  if (saved) ::setenv("SKINLAB_DATA_DIR", restore.c_str(), 1);
  testing::expect_error<ConfigError>(
      [&] { OgreBuilder::Options::from(config::Config::parse("type: ogre\npath: x\nfoo: 1\n").root()); },
      {"foo"});
}

TEST(Ogre, IsRegistered) {
  const auto cfg = config::Config::parse("type: ogre\npath: " + kBundled + "\n");
  const auto builder = dataset_registry().create(cfg.root());
  std::vector<Excluded> excluded;
  EXPECT_EQ(builder->read(excluded).size(), 2u);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::datasets

// The `folder` builder's selection and naming options (include, exclude, skeleton, prefix), its
// resolution of a `repository` source under SKINLAB_DATA_DIR with the errors a user meets
// before fetching, and the renormalisation of weights, on OBJ + rig text files the tests write;
// the bind pose and clips of assimp files (animations, fps, max_animations_per_character) on a
// glTF and a Z-up FBX the tests write.

#include "datasets/folder/folder.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <optional>

#include "framework/core/registry.hpp"
#include "framework/geometry/import_character.hpp"
#include "framework/geometry/lbs.hpp"
#include "tests/geometry/gltf_writer.hpp"
#include "tests/test_util.hpp"

namespace skinlab::datasets {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::TempDir;

const std::string kCommit = "0123456789abcdef0123456789abcdef01234567";

/// A tetrahedron bound to two joints; `weight_sum` scales the weights of vertex 0.
void write_character(const TempDir& dir, const std::string& stem, double weight_sum = 1.0) {
  dir.write(stem + ".obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  dir.write(stem + "_rig.txt",
            "joints root 0 0 0\njoints tip 0 1 0\nroot root\nhier root tip\n"
            "skin 0 root " + std::to_string(0.5 * weight_sum) + " tip " +
                std::to_string(0.5 * weight_sum) +
                "\nskin 1 root 1\nskin 2 tip 1\nskin 3 root 0.25 tip 0.75\n");
}

std::shared_ptr<DatasetBuilder> folder(const std::string& yaml) {
  return dataset_registry().create(config::Config::parse("type: folder\n" + yaml).root());
}

Folder::Options options(const std::string& yaml) {
  return Folder::Options::from(config::Config::parse("type: folder\n" + yaml).root());
}

/// Sets or unsets an environment variable for the lifetime of the object.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::optional<std::string>& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) {
      ::setenv(name, value->c_str(), 1);
    } else {
      ::unsetenv(name);
    }
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(Folder, GlobsMatchAsDocumented) {
  EXPECT_TRUE(glob_match("*.glb", "a.glb"));
  EXPECT_FALSE(glob_match("*.glb", "pack/a.glb")) << "'*' does not cross '/'";
  EXPECT_TRUE(glob_match("**/*.glb", "a.glb")) << "'**/' matches no directory too";
  EXPECT_TRUE(glob_match("**/*.glb", "pack/sub/a.glb"));
  EXPECT_TRUE(glob_match("pack/**", "pack/sub/a.glb"));
  EXPECT_FALSE(glob_match("pack/**", "other/a.glb"));
  EXPECT_TRUE(glob_match("pack_?/a.glb", "pack_1/a.glb"));
  EXPECT_FALSE(glob_match("pack_?/a.glb", "pack_12/a.glb"));
  EXPECT_TRUE(glob_match("fish/Fish3.glb", "fish/Fish3.glb"));
  EXPECT_FALSE(glob_match("fish/Fish3.glb", "fish/Fish3.glb.import"));
  EXPECT_TRUE(glob_match("*_rig*", "a_rig.txt"));
}

TEST(Folder, TodaysOptionsBehaveAsBefore) {
  TempDir dir;
  write_character(dir, "top");
  write_character(dir, "pack/inner");
  dir.write("notes.txt", "not a character");
  std::vector<Excluded> excluded;
  const auto flat = folder("path: " + dir.path().string())->read(excluded);
  ASSERT_EQ(flat.size(), 1u);
  EXPECT_EQ(flat[0].character.name, "top");
  EXPECT_EQ(flat[0].skeleton, "top") << "family: the file stem";
  EXPECT_EQ(flat[0].source, "folder");
  EXPECT_EQ(flat[0].path, "top.obj");
  EXPECT_TRUE(excluded.empty());

  const auto deep = folder("path: " + dir.path().string() + "\nrecursive: true\nskeleton: fam")
                        ->read(excluded);
  ASSERT_EQ(deep.size(), 2u);
  EXPECT_EQ(deep[0].character.name, "pack.inner");
  EXPECT_EQ(deep[0].skeleton, "fam");
  EXPECT_EQ(deep[1].character.name, "top");
}

TEST(Folder, IncludeExcludeDirectoryFamilyAndPrefix) {
  TempDir dir;
  write_character(dir, "pack_a/one");
  write_character(dir, "pack_a/chest");
  write_character(dir, "pack_b/two");
  write_character(dir, "pack_b/deep/three");
  write_character(dir, "top");
  const auto builder = folder("path: " + dir.path().string() +
                              "\ninclude: ['pack_*/*.obj', 'pack_b/deep/three.obj']"
                              "\nexclude: {pack_a/chest.obj: 'a rigged prop, not a character'}"
                              "\nskeleton: directory\nprefix: t.");
  std::vector<Excluded> excluded;
  const auto read = builder->read(excluded);
  ASSERT_EQ(read.size(), 3u);
  EXPECT_EQ(read[0].character.name, "t.pack_a.one");
  EXPECT_EQ(read[0].skeleton, "pack_a");
  EXPECT_EQ(read[1].character.name, "t.pack_b.deep.three");
  EXPECT_EQ(read[1].skeleton, "deep");
  EXPECT_EQ(read[2].character.name, "t.pack_b.two");
  EXPECT_EQ(read[2].skeleton, "pack_b");
  ASSERT_EQ(excluded.size(), 1u) << "top.obj is not included, so neither read nor excluded";
  EXPECT_EQ(excluded[0].source, "folder");
  EXPECT_EQ(excluded[0].path, "pack_a/chest.obj");
  EXPECT_EQ(excluded[0].reason, "a rigged prop, not a character");
}

TEST(Folder, PatternsThatMatchNothingAreErrors) {
  TempDir dir;
  write_character(dir, "pack/one");
  std::vector<Excluded> excluded;
  testing::expect_error<ConfigError>(
      [&] {
        folder("path: " + dir.path().string() + "\nrecursive: true\nexclude: {pack/on.obj: typo}")
            ->read(excluded);
      },
      {"exclude pattern 'pack/on.obj'", "matches no character file", dir.path().string()});
  testing::expect_error<ConfigError>(
      [&] { folder("path: " + dir.path().string() + "\ninclude: ['*.glb']")->read(excluded); },
      {"include pattern '*.glb'", "matches no character file"});
  testing::expect_error<ConfigError>(
      [&] { options("path: x\nexclude: [a.obj]"); }, {"exclude", "expected a map"});
  testing::expect_error<ConfigError>(
      [&] { options("path: x\nexclude: {a.obj: ''}"); }, {"reason must not be empty"});
}

TEST(Folder, FilesWithoutWeightsOrRigAreReported) {
  TempDir dir;
  write_character(dir, "good");
  dir.write("lonely.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  dir.write("bare.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  dir.write("bare_rig.txt", "joints root 0 0 0\njoints tip 0 1 0\nroot root\nhier root tip\n");
  std::vector<Excluded> excluded;
  const auto read = folder("path: " + dir.path().string())->read(excluded);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].character.name, "bare");
  EXPECT_FALSE(read[0].character.has_weights()) << "dropped by cleaning as 'no skin weights'";
  ASSERT_EQ(excluded.size(), 1u);
  EXPECT_EQ(excluded[0].path, "lonely.obj");
  EXPECT_NE(excluded[0].reason.find("without its RigNet rig file lonely_rig.txt"),
            std::string::npos)
      << excluded[0].reason;
}

TEST(Folder, WeightsThatDoNotSumToOneAreRenormalised) {
  TempDir dir;
  write_character(dir, "half", 0.5);
  std::vector<Excluded> excluded;
  const auto read = folder("path: " + dir.path().string())->read(excluded);
  ASSERT_EQ(read.size(), 1u) << (excluded.empty() ? "" : excluded[0].reason);
  const auto& W = read[0].character.weights;
  for (Eigen::Index v = 0; v < W.rows(); ++v) EXPECT_NEAR(W.row(v).sum(), 1.0, 1e-12);
  EXPECT_NEAR(W.coeff(0, 0), 0.5, 1e-12);
  EXPECT_NEAR(W.coeff(3, 1), 0.75, 1e-12);
}

TEST(Folder, RepositoryResolvesUnderTheDataFolder) {
  TempDir data;
  write_character(data, "owner/name/models/pack/one");
  ScopedEnv env("SKINLAB_DATA_DIR", data.path().string());
  const std::string yaml = "repository: owner/name\ncommit: " + kCommit +
                           "\npath: models\nrecursive: true\nskeleton: directory";
  const Folder builder(options(yaml));
  EXPECT_EQ(builder.root(), data.path() / "owner/name/models");
  std::vector<Excluded> excluded;
  const auto read = builder.read(excluded);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].character.name, "pack.one");
  EXPECT_EQ(read[0].source, "owner/name") << "the card lists the repository as the source";
  EXPECT_EQ(read[0].path, "pack/one.obj");
  EXPECT_EQ(read[0].skeleton, "pack");

  // Without path: the repository's root.
  EXPECT_EQ(Folder(options("repository: owner/name\ncommit: " + kCommit)).root(),
            data.path() / "owner/name");

  // A checkout at another commit is refused; at the commit (as fetch_data leaves it) accepted.
  data.write("owner/name/.git/HEAD", std::string(40, 'f') + "\n");
  testing::expect_error<IoError>([&] { builder.root(); },
                                 {"checked out at " + std::string(40, 'f'), kCommit,
                                  "scripts/fetch_data"});
  data.write("owner/name/.git/HEAD", kCommit + "\n");
  EXPECT_EQ(builder.read(excluded).size(), 1u);
}

TEST(Folder, RepositoryErrorsTellHowToFetch) {
  TempDir data;
  const std::string yaml = "repository: owner/name\ncommit: " + kCommit;
  {
    ScopedEnv env("SKINLAB_DATA_DIR", std::nullopt);
    std::vector<Excluded> excluded;
    testing::expect_error<IoError>([&] { folder(yaml)->read(excluded); },
                                   {"SKINLAB_DATA_DIR", "is not set", "owner/name", kCommit,
                                    "scripts/fetch_data"});
  }
  ScopedEnv env("SKINLAB_DATA_DIR", data.path().string());
  std::vector<Excluded> excluded;
  testing::expect_error<IoError>(
      [&] { folder(yaml)->read(excluded); },
      {"repository owner/name", "expected " + (data.path() / "owner/name").string(),
       "SKINLAB_DATA_DIR=" + data.path().string(), "scripts/fetch_data"});
}

TEST(Folder, RepositoryOptionsAreChecked) {
  testing::expect_error<ConfigError>([] { options("repository: owner/name"); },
                                     {"commit", "is required with 'repository'"});
  testing::expect_error<ConfigError>([] { options("repository: owner/name\ncommit: abc123"); },
                                     {"commit", "40 lowercase hex digits", "abc123"});
  testing::expect_error<ConfigError>([] { options("path: x\ncommit: " + kCommit); },
                                     {"commit", "only meaningful with 'repository"});
  testing::expect_error<ConfigError>([] { options("repository: owner\ncommit: " + kCommit); },
                                     {"repository", "owner/name"});
  testing::expect_error<ConfigError>(
      [] { options("repository: owner/name\ncommit: " + kCommit + "\npath: /abs"); },
      {"path", "inside the repository"});
  testing::expect_error<ConfigError>(
      [] { options("repository: owner/name\ncommit: " + kCommit + "\npath: ../other"); },
      {"path", "inside the repository"});
  testing::expect_error<ConfigError>([] { options("licence: CC0-1.0"); }, {"path"});
}

/// A 2-joint bar as glTF: root at the origin, child at y = 1 (inverse bind matrix translate(0,
/// −1, 0)); vertices (x, y) for y = 0, 1, 2, x = 0, 0.2: row 0 on root, row 1 half and half, row
/// 2 on child. Clips: "bend" turns child 0 → 90° about Z over 1 s; "grow" scales it 1 → 2.
std::string bar_gltf() {
  skinlab::testing::GltfScene s;
  s.nodes = {R"({"name":"root","children":[1]})", R"({"name":"child","translation":[0,1,0]})",
             R"({"name":"body","mesh":0,"skin":0})"};
  s.roots = {0, 2};
  skinlab::testing::GltfMesh m;
  m.name = "bar";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 2; ++c) {
      m.positions.emplace_back(0.2f * c, 1.0f * r, 0.0f);
      m.joints.push_back({0, 1, 0, 0});
      m.weights.push_back({r == 0 ? 1.0f : r == 1 ? 0.5f : 0.0f, r == 0 ? 0.0f : r == 1 ? 0.5f : 1.0f, 0, 0});
    }
  }
  m.indices = {0, 1, 2, 1, 3, 2, 2, 3, 4, 3, 5, 4};
  s.meshes = {m};
  Eigen::Matrix4f down = Eigen::Matrix4f::Identity();
  down(1, 3) = -1;
  s.skins = {skinlab::testing::GltfSkin{{0, 1}, {Eigen::Matrix4f::Identity(), down}}};
  const float h = static_cast<float>(std::sqrt(0.5));
  s.animations = {
      skinlab::testing::GltfAnimation{"bend", {{1, "rotation", {0, 1}, {0, 0, 0, 1, 0, 0, h, h}}}},
      skinlab::testing::GltfAnimation{"grow", {{1, "scale", {0, 1}, {1, 1, 1, 2, 2, 2}}}}};
  return s.json();
}

/// The same bar standing along +Z in an ASCII FBX that declares Z up (GlobalSettings UpAxis 2,
/// which assimp's FBX importer reports without rotating): child at z = 1, clip "bend" turns it
/// 0 → 90° about X over 1 s (ticks at 30 fps, TimeMode 6).
const char* kZUpBarFbx = R"(; FBX 7.5.0 project file
FBXHeaderExtension:  {
	FBXHeaderVersion: 1003
	FBXVersion: 7500
}
GlobalSettings:  {
	Version: 1000
	Properties70:  {
		P: "UpAxis", "int", "Integer", "", 2
		P: "UpAxisSign", "int", "Integer", "", 1
		P: "FrontAxis", "int", "Integer", "", 1
		P: "FrontAxisSign", "int", "Integer", "", -1
		P: "CoordAxis", "int", "Integer", "", 0
		P: "CoordAxisSign", "int", "Integer", "", 1
		P: "UnitScaleFactor", "double", "Number", "", 1
		P: "TimeMode", "enum", "", "", 6
	}
}
Objects:  {
	Geometry: 10, "Geometry::bar", "Mesh" {
		Vertices: *18 {
			a: 0,0,0, 0.2,0,0, 0,0,1, 0.2,0,1, 0,0,2, 0.2,0,2
		}
		PolygonVertexIndex: *12 {
			a: 0,1,-3, 1,3,-3, 2,3,-5, 3,5,-5
		}
		GeometryVersion: 124
	}
	Model: 20, "Model::body", "Mesh" {
		Version: 232
	}
	Model: 30, "Model::root", "LimbNode" {
		Version: 232
	}
	Model: 31, "Model::child", "LimbNode" {
		Version: 232
		Properties70:  {
			P: "Lcl Translation", "Lcl Translation", "", "A", 0, 0, 1
		}
	}
	Deformer: 40, "Deformer::", "Skin" {
		Version: 101
	}
	Deformer: 41, "SubDeformer::root", "Cluster" {
		Version: 100
		Indexes: *4 {
			a: 0,1,2,3
		}
		Weights: *4 {
			a: 1,1,0.5,0.5
		}
		Transform: *16 {
			a: 1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1
		}
		TransformLink: *16 {
			a: 1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1
		}
	}
	Deformer: 42, "SubDeformer::child", "Cluster" {
		Version: 100
		Indexes: *4 {
			a: 2,3,4,5
		}
		Weights: *4 {
			a: 0.5,0.5,1,1
		}
		Transform: *16 {
			a: 1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,-1,1
		}
		TransformLink: *16 {
			a: 1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,1,1
		}
	}
	AnimationStack: 50, "AnimStack::bend", "" {
		Properties70:  {
			P: "LocalStart", "KTime", "Time", "", 0
			P: "LocalStop", "KTime", "Time", "", 46186158000
		}
	}
	AnimationLayer: 51, "AnimLayer::base", "" {
	}
	AnimationCurveNode: 52, "AnimCurveNode::R", "" {
		Properties70:  {
			P: "d|X", "Number", "", "A", 0
			P: "d|Y", "Number", "", "A", 0
			P: "d|Z", "Number", "", "A", 0
		}
	}
	AnimationCurve: 53, "AnimCurve::", "" {
		Default: 0
		KeyVer: 4009
		KeyTime: *2 {
			a: 0,46186158000
		}
		KeyValueFloat: *2 {
			a: 0,90
		}
	}
}
Connections:  {
	C: "OO", 20, 0
	C: "OO", 10, 20
	C: "OO", 30, 0
	C: "OO", 31, 30
	C: "OO", 40, 10
	C: "OO", 41, 40
	C: "OO", 42, 40
	C: "OO", 30, 41
	C: "OO", 31, 42
	C: "OO", 51, 50
	C: "OO", 52, 51
	C: "OP", 52, 31, "Lcl Rotation"
	C: "OP", 53, 52, "d|X"
}
)";

/// LBS of `c` with frame · bind⁻¹ per joint.
Eigen::MatrixXd pose(const geometry::Character& c, const std::vector<Eigen::Isometry3d>& frame,
                     const std::vector<Eigen::Isometry3d>& bind) {
  std::vector<Eigen::Affine3d> T(bind.size());
  for (std::size_t j = 0; j < T.size(); ++j) T[j] = Eigen::Affine3d((frame[j] * bind[j].inverse()).matrix());
  return geometry::lbs(c.mesh.V, c.weights, T);
}

TEST(Folder, AssimpFilesGetTheirBindPoseAndClipsOnlyWhenAsked) {
  TempDir dir;
  dir.write("bar.gltf", bar_gltf());
  std::vector<Excluded> excluded;
  // Default: no clips (configs written before clips were read build the same characters), but
  // the bind transforms, whose translations are the joint positions.
  const auto plain = folder("path: " + dir.path().string())->read(excluded);
  ASSERT_EQ(plain.size(), 1u) << (excluded.empty() ? "" : excluded[0].reason);
  const SourceCharacter& p = plain[0];
  EXPECT_TRUE(p.animations.empty());
  ASSERT_EQ(p.bind.size(), 2u);
  for (int j = 0; j < 2; ++j) {
    EXPECT_LT((p.bind[j].translation().transpose() - p.character.skeleton.positions.row(j)).norm(), 1e-9);
  }

  const auto animated = folder("path: " + dir.path().string() + "\nanimations: true\nfps: 10")->read(excluded);
  ASSERT_EQ(animated.size(), 1u);
  const SourceCharacter& a = animated[0];
  ASSERT_EQ(a.animations.size(), 1u) << "'grow' scales the child: left out";
  const Animation& bend = a.animations[0];
  EXPECT_EQ(bend.name, "bend");
  EXPECT_EQ(bend.fps, 10.0);
  ASSERT_EQ(bend.frames.size(), 11u);
  EXPECT_EQ(bend.bind.size(), 2u);
  // At 1 s the child has turned 90° about Z around (0, 1, 0): the tip (0.2, 2) goes to (−1, 1.2).
  const Eigen::MatrixXd posed = pose(a.character, bend.frames[10], bend.bind);
  EXPECT_TRUE(posed.row(5).isApprox(Eigen::RowVector3d(-1, 1.2, 0), 1e-5)) << posed.row(5);
  EXPECT_TRUE(posed.row(0).isApprox(Eigen::RowVector3d(0, 0, 0), 1e-9)) << posed.row(0);
  EXPECT_TRUE(excluded.empty());

  const auto capped = folder("path: " + dir.path().string() +
                             "\nanimations: true\nmax_animations_per_character: 0")
                          ->read(excluded);
  ASSERT_EQ(capped.size(), 1u);
  EXPECT_TRUE(capped[0].animations.empty());
  EXPECT_EQ(capped[0].bind.size(), 2u);
}

TEST(Folder, ZUpFbxIsRotatedWithItsBindAndClips) {
  TempDir dir;
  const auto file = dir.write("zbar.fbx", kZUpBarFbx);
  // The file as assimp gives it: Z up, not rotated.
  geometry::ImportOptions import;
  import.clip_fps = 30;
  geometry::ImportReport report;
  geometry::ImportedMotion original;
  const geometry::Character c = geometry::import_character(file, import, &report, &original);
  ASSERT_TRUE(report.source_up.has_value());
  EXPECT_TRUE(report.source_up->isApprox(Eigen::Vector3d::UnitZ()));
  ASSERT_EQ(original.clips.size(), 1u);
  ASSERT_EQ(original.clips[0].frames.size(), 31u);

  std::vector<Excluded> excluded;
  const auto read = folder("path: " + dir.path().string() + "\nanimations: true\nfps: 30")->read(excluded);
  ASSERT_EQ(read.size(), 1u) << (excluded.empty() ? "" : excluded[0].reason);
  const SourceCharacter& s = read[0];
  // Blender's Z-up to Y-up turn: (x, y, z) ↦ (x, z, −y).
  Eigen::Matrix3d R;
  R << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  EXPECT_TRUE(s.character.mesh.V.isApprox(c.mesh.V * R.transpose(), 1e-12));
  EXPECT_TRUE(s.character.skeleton.positions.row(1).isApprox(Eigen::RowVector3d(0, 1, 0), 1e-9));
  ASSERT_EQ(s.bind.size(), 2u);
  for (int j = 0; j < 2; ++j) {
    EXPECT_LT((s.bind[j].translation().transpose() - s.character.skeleton.positions.row(j)).norm(), 1e-9);
  }
  ASSERT_EQ(s.animations.size(), 1u);
  const Animation& bend = s.animations[0];
  ASSERT_EQ(bend.frames.size(), 31u);
  // LBS in the rotated frame is the rotated LBS of the file's frame, at every frame.
  double worst = 0;
  for (std::size_t f = 0; f < bend.frames.size(); ++f) {
    const Eigen::MatrixXd rotated = pose(s.character, bend.frames[f], bend.bind);
    const Eigen::MatrixXd in_file = pose(c, original.clips[0].frames[f], original.bind);
    worst = std::max(worst, (rotated - in_file * R.transpose()).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-9);
  // At 1 s the child has turned 90° about the file's X: the tip (x, 0, 2) goes to (x, −1, 1) in
  // the file, (x, 1, 1) once Y is up; the middle row stays at (x, 1, 0).
  const Eigen::MatrixXd last = pose(s.character, bend.frames[30], bend.bind);
  EXPECT_TRUE(last.row(5).isApprox(Eigen::RowVector3d(0.2, 1, 1), 1e-5)) << last.row(5);
  EXPECT_TRUE(last.row(3).isApprox(Eigen::RowVector3d(0.2, 1, 0), 1e-5)) << last.row(3);
}

TEST(Folder, AnimationOptionsAreChecked) {
  testing::expect_error<ConfigError>([] { options("path: x\nfps: 0"); }, {"fps", "positive"});
  testing::expect_error<ConfigError>([] { options("path: x\nmax_animations_per_character: -1"); },
                                     {"max_animations_per_character", "≥ 0"});
  const Folder::Options o = options("path: x");
  EXPECT_FALSE(o.animations);
  EXPECT_EQ(o.max_animations_per_character, 8);
  EXPECT_EQ(o.fps, 24.0);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::datasets

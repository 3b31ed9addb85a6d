// The 0 A.D. source on the bundled real subset (datasets/zeroad/bundled, CC-BY-SA 3.0,
// Wildfire Games): PMD/PSA/skeleton parsers, LBS round trips and the `zeroad` builder.
#include <gtest/gtest.h>
#include <zip.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "../geometry/test_meshes.hpp"
#include "../test_util.hpp"
#include "datasets/zeroad/package.hpp"
#include "datasets/zeroad/read_actor.hpp"
#include "datasets/zeroad/read_pmd.hpp"
#include "datasets/zeroad/read_psa.hpp"
#include "datasets/zeroad/read_skeletons.hpp"
#include "datasets/zeroad/zeroad.hpp"
#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/geometry/lbs.hpp"

namespace skinlab::datasets {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using namespace zeroad;

const std::string kBundled = std::string(SKINLAB_SOURCE_DIR) + "/datasets/zeroad/bundled";
const std::string kTunic = "art/meshes/skeletal/new/m_tunic_short.dae.cached.pmd";

std::string read_bundled(const std::string& entry) { return Package(kBundled).read(entry); }

::testing::AssertionResult throws_with(const std::function<void()>& f,
                                       const std::vector<std::string>& parts) {
  try {
    f();
  } catch (const Error& e) {
    const std::string msg = e.what();
    for (const auto& p : parts)
      if (msg.find(p) == std::string::npos)
        return ::testing::AssertionFailure() << "message '" << msg << "' lacks '" << p << "'";
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "no skinlab::Error thrown";
}

/// Builds the bundled dataset once for all tests.
struct Built {
  std::vector<SourceCharacter> characters;
  std::vector<Excluded> excluded;
  const SourceCharacter& get(const std::string& name) const {
    for (const auto& c : characters)
      if (c.character.name == name) return c;
    throw std::runtime_error("no character " + name);
  }
};
const Built& built() {
  static const Built b = [] {
    Built out;
    ZeroAdBuilder::Options o;
    o.path = kBundled;
    out.characters = ZeroAdBuilder(o).read(out.excluded);
    return out;
  }();
  return b;
}

double diagonal(const Eigen::MatrixXd& V) {
  return (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
}

TEST(ZeroAdPmd, ParsesBundledBiped) {
  const Pmd pmd = read_pmd(read_bundled(kTunic), kTunic);
  EXPECT_EQ(pmd.version, 4);
  EXPECT_EQ(pmd.positions.rows(), 668);
  EXPECT_EQ(pmd.faces.rows(), 932);
  EXPECT_EQ(pmd.uvs.cols(), 2);
  EXPECT_EQ(pmd.num_bones(), 46);
  EXPECT_EQ(pmd.props.size(), 53u);
  EXPECT_EQ(pmd.props[0].name, "root");
  EXPECT_EQ(pmd.props[0].bone, -1);
  EXPECT_LT(pmd.bone_indices.maxCoeff(), 46);
  for (Eigen::Index v = 0; v < pmd.positions.rows(); ++v) {
    EXPECT_GE(pmd.bone_indices(v, 0), 0) << "vertex " << v;
    EXPECT_NEAR(pmd.bone_weights.row(v).sum(), 1.0, 1e-3) << "vertex " << v;
    EXPECT_NEAR(pmd.normals.row(v).norm(), 1.0, 1e-2) << "vertex " << v;
  }
  // A standing human in game units: about 2 tall, feet near y = 0.
  const Eigen::Vector3d lo = pmd.positions.colwise().minCoeff(),
                        hi = pmd.positions.colwise().maxCoeff();
  EXPECT_GT(hi.y() - lo.y(), 1.0);
  EXPECT_LT(hi.y() - lo.y(), 4.0);
  EXPECT_NEAR(lo.y(), 0.0, 0.3);
}

TEST(ZeroAdPmd, StaticMeshHasNoBones) {
  const std::string entry = "art/meshes/skeletal/walrus.dae.cached.pmd";
  const Pmd pmd = read_pmd(read_bundled(entry), entry);
  EXPECT_EQ(pmd.num_bones(), 0);
  EXPECT_EQ(pmd.positions.rows(), 134);
  EXPECT_EQ(pmd.bone_indices.maxCoeff(), -1);
}

TEST(ZeroAdPmd, MalformedBytesNameFileAndOffset) {
  const std::string bytes = read_bundled(kTunic);
  // Cut inside vertex 10: header 12, #V 4, #UV 4, then 52 bytes per vertex.
  const std::size_t cut = 12 + 8 + 10 * 52 + 30;
  EXPECT_TRUE(throws_with([&] { read_pmd(bytes.substr(0, cut), "m_tunic_short.pmd"); },
                          {"m_tunic_short.pmd", "byte offset " + std::to_string(12 + 8 + 10 * 52),
                           "vertex 10 of 668", "truncated"}));
  // Cut in the bone block.
  EXPECT_TRUE(throws_with([&] { read_pmd(bytes.substr(0, bytes.size() - 3000), "cut.pmd"); },
                          {"cut.pmd", "byte offset"}));
  std::string bad_magic = bytes;
  bad_magic[0] = 'X';
  EXPECT_TRUE(throws_with([&] { read_pmd(bad_magic, "magic.pmd"); },
                          {"magic.pmd", "byte offset 0", "not a PSMD file"}));
  std::string bad_version = bytes;
  bad_version[4] = 9;
  EXPECT_TRUE(throws_with([&] { read_pmd(bad_version, "v.pmd"); },
                          {"v.pmd", "byte offset 4", "unsupported PMD version 9"}));
  // Vertex 3's second influence names bone 200 of 46.
  std::string bad_bone = bytes;
  const std::size_t bone_byte = 12 + 8 + 3 * 52 + 32 + 1;
  bad_bone[bone_byte] = static_cast<char>(200);
  EXPECT_TRUE(throws_with([&] { read_pmd(bad_bone, "bone.pmd"); },
                          {"bone.pmd", "byte offset " + std::to_string(bone_byte), "vertex 3",
                           "bone index 200", "46 bones"}));
  EXPECT_TRUE(
      throws_with([&] { read_pmd(bytes + "xx", "tail.pmd"); }, {"tail.pmd", "trailing bytes"}));
  EXPECT_TRUE(throws_with([&] { read_pmd("PSM", "tiny.pmd"); }, {"tiny.pmd", "byte offset 0"}));
}

TEST(ZeroAdPsa, ParsesBundledClipAndRejectsTruncation) {
  const std::string entry = "art/animation/quadraped/horse_gallop.dae.cached.psa";
  const std::string bytes = read_bundled(entry);
  const Psa psa = read_psa(bytes, entry);
  EXPECT_EQ(psa.num_bones, 49);
  EXPECT_EQ(psa.frames.size(), 9u);
  EXPECT_NEAR(psa.frame_time_ms, 1000.0 / 30.0, 1e-3);
  for (const auto& frame : psa.frames) ASSERT_EQ(frame.size(), 49u);
  EXPECT_TRUE(throws_with([&] { read_psa(bytes.substr(0, bytes.size() - 100), "gallop.psa"); },
                          {"gallop.psa", "byte offset", "frame 8"}));
}

TEST(ZeroAdSkeletons, BipedStandardTreeAndTargets) {
  const std::string entry = "art/skeletons/biped.xml";
  const SkeletonFile file = read_skeletons(read_bundled(entry), entry);
  ASSERT_FALSE(file.standard.empty());
  const StandardSkeleton& s = file.standard[0];
  EXPECT_EQ(s.id, "Biped");
  ASSERT_EQ(s.names.size(), 46u);
  EXPECT_EQ(s.names[0], "hip");
  EXPECT_EQ(s.names[1], "spine");
  EXPECT_EQ(s.parents[1], 0);
  std::vector<std::string> top;
  for (std::size_t i = 0; i < s.names.size(); ++i)
    if (s.parents[i] < 0) top.push_back(s.names[i]);
  EXPECT_EQ(top, (std::vector<std::string>{"hip", "knee_L", "knee_R", "elbow_L", "elbow_R"}));
  const auto at = [&](const std::string& n) {
    return std::find(s.names.begin(), s.names.end(), n) - s.names.begin();
  };
  EXPECT_EQ(s.parents[at("fingertip_L")], at("finger_L"));
  EXPECT_EQ(s.parents[at("foot_R")], at("leg_R"));
  ASSERT_FALSE(file.mapped.empty());
  for (const auto& t : file.mapped) {
    EXPECT_EQ(t.target, "Biped");
    EXPECT_FALSE(t.root.empty());
    EXPECT_EQ(t.names.size(), t.targets.size());
  }
}

TEST(ZeroAdSkeletons, MalformedXmlNamesFileAndLine) {
  EXPECT_TRUE(throws_with(
      [] { read_skeletons("<skeletons>\n<standard_skeleton id='a'>\n<bone>", "s.xml"); },
      {"s.xml:3", "XML error"}));
  EXPECT_TRUE(throws_with(
      [] {
        read_skeletons(
            "<skeletons>\n<standard_skeleton id='a'>\n<bone/></standard_skeleton></skeletons>",
            "n.xml");
      },
      {"n.xml:3", "bone without name"}));
  EXPECT_TRUE(throws_with(
      [] {
        read_skeletons(
            "<skeletons><standard_skeleton id='a'><bone name='x'><bone name='x'/></bone>"
            "</standard_skeleton></skeletons>",
            "d.xml");
      },
      {"d.xml:1", "duplicate bone 'x'"}));
}

// A million nested elements (7 MB) overflowed the stack while the element tree was built and
// destroyed recursively (found by a crafted input alongside the reader fuzzing; exit 139 of
// `skinlab prepare`); nesting deeper than 256 is now rejected at the element that goes too deep.
TEST(ZeroAdSkeletons, DeepNestingIsRejectedNotAStackOverflow) {
  std::string xml = "<skeletons>\n";
  for (int i = 0; i < 1000000; ++i) xml += "<b>";
  for (int i = 0; i < 1000000; ++i) xml += "</b>";
  xml += "</skeletons>\n";
  EXPECT_TRUE(throws_with([&] { read_skeletons(xml, "deep.xml"); },
                          {"deep.xml:2: <b>", "nested more than 256 deep"}));
}

TEST(ZeroAdActor, CollectsMeshesAnimationsAndVariants) {
  const ActorRefs refs = read_actor(
      "<actor version='1'><group><variant><mesh>skeletal/horse.dae</mesh></variant></group>"
      "<group><variant file='quadraped/base_horse_run.xml'/><variant name='x'><animations>"
      "<animation file='quadraped/horse_idle_01.dae' name='Idle'/></animations></variant></group>"
      "</actor>",
      "a.xml");
  EXPECT_EQ(refs.meshes, std::vector<std::string>{"skeletal/horse.dae"});
  ASSERT_EQ(refs.animations.size(), 1u);
  EXPECT_EQ(refs.animations[0].file, "quadraped/horse_idle_01.dae");
  EXPECT_EQ(refs.animations[0].name, "Idle");
  EXPECT_EQ(refs.variant_files, std::vector<std::string>{"quadraped/base_horse_run.xml"});
}

TEST(ZeroAdPackage, ListsAndReadsDirectoryAndRejectsMissingPath) {
  const Package pkg(kBundled);
  const auto pmds = pkg.list("art/meshes/skeletal/", ".pmd");
  EXPECT_EQ(pmds.size(), 16u);
  EXPECT_TRUE(std::is_sorted(pmds.begin(), pmds.end()));
  EXPECT_TRUE(pkg.contains(kTunic));
  EXPECT_TRUE(throws_with([&] { pkg.read("art/none.pmd"); }, {"no entry 'art/none.pmd'"}));
  EXPECT_TRUE(
      throws_with([] { Package p("/nonexistent/public.zip"); }, {"/nonexistent/public.zip"}));
}

/// Packs `entries` of the bundled tree into a zip archive at `file` with libzip (deflated, as
/// Debian's public.zip is), so the archive path of Package is tested without the 3.2 GB package.
void write_zip(const std::filesystem::path& file, const std::vector<std::string>& entries,
               std::vector<std::string>& keep_alive) {
  int error = 0;
  zip_t* z = zip_open(file.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  ASSERT_NE(z, nullptr) << "zip_open error " << error;
  for (const auto& e : entries) {
    keep_alive.push_back(Package(kBundled).read(e));
    zip_source_t* src = zip_source_buffer(z, keep_alive.back().data(), keep_alive.back().size(), 0);
    ASSERT_NE(src, nullptr);
    ASSERT_GE(zip_file_add(z, e.c_str(), src, ZIP_FL_ENC_UTF_8), 0) << zip_strerror(z);
  }
  ASSERT_EQ(zip_close(z), 0);
}

TEST(ZeroAdPackage, ReadsTheZipArchiveLikeTheDirectory) {
  skinlab::testing::TempDir dir;
  const Package tree(kBundled);
  std::vector<std::string> entries = tree.list("art/skeletons/", ".xml");
  entries.push_back(kTunic);
  std::vector<std::string> buffers;
  write_zip(dir / "public.zip", entries, buffers);
  const Package zip(dir / "public.zip");
  EXPECT_EQ(zip.list("art/skeletons/", ".xml"), tree.list("art/skeletons/", ".xml"));
  EXPECT_EQ(zip.list("art/meshes/skeletal/", ".pmd"), std::vector<std::string>{kTunic});
  for (const auto& e : entries) EXPECT_EQ(zip.read(e), tree.read(e)) << e;
  EXPECT_TRUE(throws_with([&] { zip.read("art/none.pmd"); }, {"art/none.pmd"}));
  // A regular file that is not a zip archive is rejected with its path.
  std::ofstream(dir / "broken.zip") << "not a zip archive";
  EXPECT_TRUE(throws_with([&] { Package p(dir / "broken.zip"); }, {"broken.zip"}));
}

const std::set<std::string> kExpectedNames = {
    "animal_lion",         "animal_tuna",   "camel_1",       "cattle_male_a", "crow",
    "elephant_asian_male", "f_dress",       "giraffe_adult", "goat",          "horse",
    "m_armor_pants",       "m_tunic_short", "wolf"};

TEST(ZeroAdBuilder, BundledCharactersValidatedWithExpectedExclusions) {
  const Built& b = built();
  std::set<std::string> names;
  for (const auto& sc : b.characters) {
    names.insert(sc.character.name);
    EXPECT_EQ(sc.source, "zeroad");
    EXPECT_EQ(sc.licence, "CC-BY-SA-3.0");
    EXPECT_EQ(sc.attribution, "Wildfire Games (0 A.D.)");
    EXPECT_EQ(sc.path.rfind("art/meshes/skeletal/", 0), 0u) << sc.path;
    geometry::Character c = sc.character;
    EXPECT_NO_THROW(c.validate()) << c.name;
    EXPECT_EQ(c.weights.cols(), c.skeleton.num_joints());
  }
  EXPECT_EQ(names, kExpectedNames);
  EXPECT_EQ(built().get("m_tunic_short").skeleton, "Biped");
  EXPECT_EQ(built().get("f_dress").skeleton, "Biped");
  EXPECT_EQ(built().get("m_tunic_short").character.skeleton.num_joints(), 46);
  EXPECT_EQ(built().get("horse").character.skeleton.num_joints(), 49);

  std::map<std::string, std::string> reasons;
  for (const auto& e : b.excluded) reasons[e.path] = e.reason;
  ASSERT_EQ(reasons.size(), 3u);
  EXPECT_NE(reasons["art/meshes/skeletal/walrus.dae.cached.pmd"].find("no bones"),
            std::string::npos);
  EXPECT_NE(reasons["art/meshes/skeletal/bird_circle.dae.cached.pmd"].find("rigid"),
            std::string::npos);
  // The hawk's own clips contradict every 9-bone tree: its match is not verified.
  const std::string hawk = reasons["art/meshes/skeletal/hawk.dae.cached.pmd"];
  EXPECT_NE(hawk.find("no skeleton"), std::string::npos) << hawk;
  EXPECT_NE(hawk.find("clip check"), std::string::npos) << hawk;
}

TEST(ZeroAdBuilder, AttachesActorClips) {
  const auto& horse = built().get("horse");
  ASSERT_FALSE(horse.animations.empty());
  for (const auto& a : horse.animations) {
    EXPECT_GT(a.fps, 0);
    ASSERT_FALSE(a.frames.empty());
    EXPECT_EQ(a.frames[0].size(), 49u);
    EXPECT_EQ(a.bind.size(), 49u);
    EXPECT_EQ(a.name.rfind("quadraped/", 0), 0u) << a.name;
  }
  EXPECT_FALSE(built().get("wolf").animations.empty());
  EXPECT_FALSE(built().get("m_tunic_short").animations.empty());
  EXPECT_TRUE(built().get("cattle_male_a").animations.empty());  // no actor names it
  // Every character keeps its PMD's bind pose, with or without clips.
  for (const auto& sc : built().characters) {
    ASSERT_EQ(sc.bind.size(), static_cast<std::size_t>(sc.character.skeleton.num_joints()))
        << sc.character.name;
    const Pmd pmd = read_pmd(read_bundled(sc.path), sc.path);
    for (std::size_t j = 0; j < sc.bind.size(); ++j) {
      EXPECT_TRUE(sc.bind[j].isApprox(pmd.bind[j], 0.0)) << sc.character.name << " " << j;
    }
  }
}

TEST(ZeroAdLbs, BindPoseReproducesEveryMesh) {
  for (const auto& sc : built().characters) {
    const auto& c = sc.character;
    // Animation convention: T_j = G_j · bind_j⁻¹ with G = bind is the identity.
    std::vector<Eigen::Affine3d> T;
    const Pmd pmd = read_pmd(read_bundled(sc.path), sc.path);
    for (const auto& b : pmd.bind) T.emplace_back((b * b.inverse()).matrix());
    const Eigen::MatrixXd P = geometry::lbs(c.mesh.V, c.weights, T);
    EXPECT_LT((P - c.mesh.V).cwiseAbs().maxCoeff(), 1e-3 * diagonal(c.mesh.V)) << c.name;
    // joint j sits at PMD bone j's bind translation
    for (int j = 0; j < c.skeleton.num_joints(); ++j)
      EXPECT_LT((c.skeleton.positions.row(j).transpose() - pmd.bind[j].translation()).norm(), 1e-9);
  }
}

/// Poses a character with frame f of an animation (T_j = G_j(f) · bind_j⁻¹), relative to the
/// root joint's motion so that travelling clips compare with the bind pose.
Eigen::MatrixXd pose(const SourceCharacter& sc, const Animation& a, std::size_t f) {
  const auto& c = sc.character;
  const int root = c.skeleton.root();
  const Eigen::Isometry3d root_motion = a.frames[f][root] * a.bind[root].inverse();
  std::vector<Eigen::Affine3d> T;
  for (int j = 0; j < c.skeleton.num_joints(); ++j)
    T.emplace_back((root_motion.inverse() * a.frames[f][j] * a.bind[j].inverse()).matrix());
  return geometry::lbs(c.mesh.V, c.weights, T);
}

TEST(ZeroAdLbs, ClipFramesMoveMeshesPlausibly) {
  for (const std::string name : {"horse", "wolf", "m_tunic_short"}) {
    const auto& sc = built().get(name);
    const auto& c = sc.character;
    const double diag = diagonal(c.mesh.V);
    ASSERT_FALSE(sc.animations.empty()) << name;
    for (const auto& a : sc.animations) {
      double largest = 0;
      for (std::size_t f = 0; f < a.frames.size(); ++f) {
        const Eigen::MatrixXd P = pose(sc, a, f);
        const double move = (P - c.mesh.V).rowwise().norm().maxCoeff();
        largest = std::max(largest, move);
        EXPECT_LT(move, 0.75 * diag) << name << " " << a.name << " frame " << f;
        // Skinning with the right rotations keeps edges nearly rigid on average (the transposed
        // rotations give 0.3–0.7 on these clips; rider poses reach 0.14 with the right ones).
        double stretch = 0;
        int edges = 0;
        for (int i = 0; i < c.mesh.num_faces(); ++i)
          for (int k = 0; k < 3; ++k) {
            const int u = c.mesh.F(i, k), v = c.mesh.F(i, (k + 1) % 3);
            const double l0 = (c.mesh.V.row(u) - c.mesh.V.row(v)).norm();
            if (l0 < 1e-6 * diag) continue;
            stretch += std::abs((P.row(u) - P.row(v)).norm() - l0) / l0;
            ++edges;
          }
        EXPECT_LT(stretch / edges, 0.2) << name << " " << a.name << " frame " << f;
      }
      EXPECT_GT(largest, 0.01 * diag) << name << " " << a.name << ": the clip should move the mesh";
    }
  }
}

// make_right_handed (data/source.hpp) reads the game's left-handed frame as the right-handed
// mirror image another program shows: the horse faces +Z with its left hooves at +X and outward
// faces, and every position, bind transform and clip frame is the game frame's mirrored front to
// back, so that a clip poses the mirrored mesh into the mirror image of the pose.
TEST(ZeroAdFrame, RightHandedIsTheMirrorImageOfTheGameFrame) {
  const Eigen::Vector3d flip(1, 1, -1);
  for (const SourceCharacter& game : built().characters) {
    SourceCharacter rh = game;
    make_right_handed(rh);
    const std::string& name = rh.character.name;
    EXPECT_TRUE(game.left_handed) << name;
    EXPECT_FALSE(rh.left_handed) << name;
    EXPECT_EQ(rh.character.mesh.V, Eigen::MatrixXd(game.character.mesh.V * flip.asDiagonal())) << name;
    EXPECT_EQ(rh.character.mesh.F, game.character.mesh.F) << name;
    EXPECT_EQ(rh.character.skeleton.positions,
              Eigen::MatrixXd(game.character.skeleton.positions * flip.asDiagonal())) << name;
    ASSERT_EQ(rh.bind.size(), game.bind.size()) << name;
    for (std::size_t j = 0; j < rh.bind.size(); ++j) {
      EXPECT_EQ(Eigen::Vector3d(rh.bind[j].translation()),
                Eigen::Vector3d(flip.cwiseProduct(game.bind[j].translation())))
          << name << " " << j;
      EXPECT_NEAR(rh.bind[j].linear().determinant(), 1.0, 1e-9) << name << " " << j;
    }
    ASSERT_EQ(rh.animations.size(), game.animations.size()) << name;
    for (std::size_t a = 0; a < rh.animations.size(); ++a) {
      ASSERT_EQ(rh.animations[a].frames.size(), game.animations[a].frames.size());
      for (std::size_t f = 0; f < rh.animations[a].frames.size(); f += 7) {
        const Eigen::MatrixXd posed = pose(rh, rh.animations[a], f);
        const Eigen::MatrixXd expected = pose(game, game.animations[a], f) * flip.asDiagonal();
        EXPECT_LT((posed - expected).cwiseAbs().maxCoeff(), 1e-9 * diagonal(expected))
            << name << " " << rh.animations[a].name << " frame " << f;
      }
    }
    // A right-handed character is left as it is.
    SourceCharacter again = rh;
    make_right_handed(again);
    EXPECT_EQ(again.character.mesh.V, rh.character.mesh.V) << name;
  }
  SourceCharacter horse = built().get("horse");
  EXPECT_LT(testing::signed_volume(horse.character.mesh.V, horse.character.mesh.F), 0);
  make_right_handed(horse);
  const auto joint = [&](const std::string& n) {
    const int j = horse.character.skeleton.find(n);
    EXPECT_GE(j, 0) << n;
    return Eigen::Vector3d(horse.character.skeleton.positions.row(std::max(j, 0)));
  };
  EXPECT_GT(joint("head").z(), joint("tail").z());
  EXPECT_GT(joint("l_hoof").x(), 0);
  EXPECT_LT(joint("r_hoof").x(), 0);
  EXPECT_GT(testing::signed_volume(horse.character.mesh.V, horse.character.mesh.F), 0);
}

TEST(ZeroAdBuilder, OptionsFromConfig) {
  auto cfg = config::Config::parse("type: zeroad\npath: " + kBundled +
                                   "\nanimations: true\nmax_animations_per_character: 1\n");
  auto builder = dataset_registry().create(cfg.root());
  std::vector<Excluded> excluded;
  for (const auto& sc : builder->read(excluded))
    EXPECT_LE(sc.animations.size(), 1u) << sc.character.name;

  auto off = config::Config::parse("type: zeroad\npath: " + kBundled + "\nanimations: false\n");
  excluded.clear();
  for (const auto& sc : dataset_registry().create(off.root())->read(excluded))
    EXPECT_TRUE(sc.animations.empty());

  auto typo = config::Config::parse("type: zeroad\nanimation: false\n");
  EXPECT_THROW(dataset_registry().create(typo.root()), ConfigError);
  auto negative = config::Config::parse("type: zeroad\nmax_animations_per_character: -1\n");
  EXPECT_THROW(dataset_registry().create(negative.root()), ConfigError);
  auto missing = config::Config::parse("type: zeroad\npath: /nonexistent/dir\n");
  EXPECT_THROW(dataset_registry().create(missing.root())->read(excluded), IoError);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::datasets

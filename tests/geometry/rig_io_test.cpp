// RigNet rig text and OBJ files: round trips and every malformed-line error with its line number.

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <sstream>

#include "framework/core/atomic_file.hpp"
#include "framework/geometry/load_character.hpp"
#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/rig_io.hpp"
#include "tests/test_util.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using skinlab::testing::TempDir;

const char* kObj =
    "# a quad split in two and a stray comment\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
    "f 1/1/1 2/1/1 3/1/1 4/1/1\n";

const char* kRig =
    "joints hips 0 0.5 0\n"
    "joints spine 0 1 0\n"
    "joints head 0 1.5 0.25\n"
    "root hips\n"
    "hier hips spine\n"
    "hier spine head\n"
    "skin 0 hips 1.0\n"
    "skin 1 hips 0.25 spine 0.75\n"
    "skin 2 spine 0.3333333333333333 head 0.6666666666666667\n"
    "skin 3 head 1\n";

TEST(ObjIo, ReadsPolygonsAsFansAndRoundTrips) {
  TempDir dir;
  const Mesh mesh = read_obj(dir.write("quad.obj", kObj));
  ASSERT_EQ(mesh.num_vertices(), 4);
  ASSERT_EQ(mesh.num_faces(), 2);
  EXPECT_EQ(mesh.F.row(1), Eigen::RowVector3i(0, 2, 3));
  const Mesh negative = read_obj(dir.write("neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"));
  EXPECT_EQ(negative.F.row(0), Eigen::RowVector3i(0, 1, 2));

  Mesh odd = mesh;
  odd.V(2, 1) = 0.1 + 0.2;  // not exactly representable in short decimal form
  write_obj(dir / "out.obj", odd);
  const Mesh again = read_obj(dir / "out.obj");
  EXPECT_EQ(again.V, odd.V);
  EXPECT_EQ(again.F, odd.F);
}

TEST(ObjIo, ErrorsNameFileAndLine) {
  TempDir dir;
  expect_error<GeometryError>([&] { read_obj(dir.write("a.obj", "v 0 0 0\nv 1 x 0\n")); },
                              {"a.obj:2: bad coordinate 'x'"});
  expect_error<GeometryError>([&] { read_obj(dir.write("b.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n")); },
                              {"b.obj:3: face needs at least 3 vertices"});
  expect_error<GeometryError>(
      [&] { read_obj(dir.write("c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n")); },
      {"c.obj:4: face vertex 4 is out of range (3 vertices so far)"});
  expect_error<GeometryError>([&] { read_obj(dir.write("d.obj", "v 0 0 0\nf 0 1 1\n")); },
                              {"d.obj:2: bad face vertex '0'"});
  expect_error<GeometryError>([&] { read_obj(dir.write("e.obj", "v 0 0 0\n")); },
                              {"e.obj: mesh has no faces"});
  expect_error<IoError>([&] { read_obj(dir / "absent.obj"); }, {"absent.obj", "cannot open"});
}

TEST(RigIo, ReadsSkeletonAndWeights) {
  TempDir dir;
  const Rig rig = read_rig(dir.write("r.txt", kRig), 4);
  EXPECT_EQ(rig.skeleton.names, (std::vector<std::string>{"hips", "spine", "head"}));
  EXPECT_EQ(rig.skeleton.parents, (std::vector<int>{-1, 0, 1}));
  EXPECT_DOUBLE_EQ(rig.skeleton.positions(2, 2), 0.25);
  EXPECT_DOUBLE_EQ(rig.weights.coeff(1, 1), 0.75);
  EXPECT_DOUBLE_EQ(rig.weights.coeff(3, 2), 1.0);
  EXPECT_EQ(rig.weights.nonZeros(), 6);
}

TEST(RigIo, RoundTripIsBitIdentical) {
  TempDir dir;
  const Character c = read_obj_rig(dir.write("hero.obj", kObj), dir.write("hero_rig.txt", kRig));
  EXPECT_EQ(c.name, "hero");
  write_rig(dir / "again.txt", c.skeleton, c.weights);
  const Rig again = read_rig(dir / "again.txt", c.mesh.num_vertices());
  EXPECT_EQ(again.skeleton.names, c.skeleton.names);
  EXPECT_EQ(again.skeleton.parents, c.skeleton.parents);
  EXPECT_EQ(again.skeleton.positions, c.skeleton.positions);
  EXPECT_EQ(Eigen::MatrixXd(again.weights), Eigen::MatrixXd(c.weights));
}

TEST(RigIo, SkeletonOnlyFile) {
  TempDir dir;
  const Rig rig = read_rig(dir.write("s.txt", "joints a 0 0 0\njoints b 0 1 0\nroot a\nhier a b\n"), 10);
  EXPECT_EQ(rig.skeleton.num_joints(), 2);
  EXPECT_EQ(rig.weights.rows(), 0);
}

TEST(RigIo, MalformedLinesNameTheLine) {
  TempDir dir;
  const std::string head = "joints a 0 0 0\njoints b 0 1 0\nroot a\nhier a b\n";  // lines 1-4
  struct Case {
    std::string text;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"joints a 0 0\n", ":1: expected 'joints NAME x y z'"},
      {"joints a 0 zero 0\n", ":1: bad coordinate 'zero'"},
      {"joints a 0 0 0\njoints a 1 1 1\n", ":2: duplicate joint 'a'"},
      {head + "root b\n", ":5: second root line (first on line 3)"},
      {"joints a 0 0 0\nroot z\n", ":2: unknown joint 'z'"},
      {head + "hier z b\n", ":5: unknown joint 'z'"},
      {head + "hier b a\nhier a b\n", ":6: joint 'b' already has parent 'a' (line 4)"},
      {head + "skin 0 a\n", ":5: expected 'skin VID JOINT WEIGHT"},
      {head + "skin 9 a 1\n", ":5: vertex 9 is out of range (the mesh has 2 vertices)"},
      {head + "skin -1 a 1\n", ":5: vertex -1 is out of range"},
      {head + "skin 0 a 1\nskin 0 b 1\n", ":6: vertex 0 already has weights (line 5)"},
      {head + "skin 0 c 1\n", ":5: unknown joint 'c'"},
      {head + "skin 0 a one\n", ":5: bad weight 'one'"},
      {head + "bone a b\n", ":5: unknown statement 'bone'"},
      {head + "skin 0 a 1\n", "vertex 1 has no weight"},
      {head + "skin 0 a 0.5\nskin 1 b 1\n", "vertex 0: weights sum to 0.5"},
      {head + "skin 0 a -1 b 2\nskin 1 b 1\n", "vertex 0, joint 'a': negative weight"},
      {head + "skin 0 a 0.5 a 0.5\nskin 1 b 1\n", "names the same joint twice"},
      {"joints a 0 0 0\njoints b 0 1 0\nroot a\n", "joint 'b' has no 'hier' line and is not the root 'a'"},
      {"joints a 0 0 0\njoints b 0 1 0\nroot a\nhier b a\n", "root 'a' has a parent ('b', line 4)"},
      {"joints a 0 0 0\nhier a a\n", "no 'root' line"},
      {"root a\n", ":1: unknown joint 'a'"},
      {"", "no 'joints' lines"},
  };
  int n = 0;
  for (const auto& c : cases) {
    const auto file = dir.write("case" + std::to_string(n++) + ".txt", c.text);
    expect_error<GeometryError>([&] { read_rig(file, 2); }, {file.filename().string(), c.message});
  }
}

/// Collects what is logged while it lives (the default logger is restored after).
class LogCapture {
 public:
  LogCapture() : previous_(spdlog::default_logger()) {
    auto logger = std::make_shared<spdlog::logger>(
        "capture", std::make_shared<spdlog::sinks::ostream_sink_st>(stream_));
    logger->set_pattern("[%l] %v");
    spdlog::set_default_logger(logger);
  }
  ~LogCapture() { spdlog::set_default_logger(previous_); }
  /// The lines logged at `level` ("warning", "info", ...).
  std::vector<std::string> lines(const std::string& level) const {
    std::vector<std::string> found;
    std::istringstream in(stream_.str());
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("[" + level + "] ", 0) == 0) found.push_back(line);
    }
    return found;
  }

 private:
  std::ostringstream stream_;
  std::shared_ptr<spdlog::logger> previous_;
};

TEST(RigIo, IgnoringSkinLinesKeepsTheSkeletonAndWarnsOnceWithTheStrictError) {
  TempDir dir;
  const std::string head = "joints a 0 0 0\njoints b 0 1 0\nroot a\nhier a b\n";  // lines 1-4
  // Every kind of skin-line problem: under `ignore_mismatch` the skeleton comes back without
  // weights, and the warning is the error `require` throws.
  const std::vector<std::string> skin_cases = {
      head + "skin 0 a\n",
      head + "skin 9 a 1\nskin 0 a 1\nskin 10 b 1\n",
      head + "skin 0 a 1\nskin 0 b 1\n",
      head + "skin 0 c 1\nskin 1 b 1\n",
      head + "skin 0 a one\n",
      head + "skin 0 a 1\n",
      head + "skin 0 a 0.5\nskin 1 b 1\n",
      head + "skin 0 a -1 b 2\nskin 1 b 1\n",
      head + "skin 0 a 0.5 a 0.5\nskin 1 b 1\n",
      // skin lines before the skeleton's last lines: the skeleton is still read whole
      "joints a 0 0 0\njoints b 0 1 0\nskin 5 a 1\nroot a\nhier a b\n",
  };
  int n = 0;
  for (const auto& text : skin_cases) {
    const auto file = dir.write("skin" + std::to_string(n++) + ".txt", text);
    std::string strict;
    try {
      read_rig(file, 2);
    } catch (const GeometryError& e) {
      strict = e.what();
    }
    ASSERT_FALSE(strict.empty()) << text;
    LogCapture log;
    const Rig rig = read_rig(file, 2, {}, SkinLines::ignore_mismatch);
    EXPECT_EQ(rig.skeleton.names, (std::vector<std::string>{"a", "b"})) << text;
    EXPECT_EQ(rig.skeleton.parents, (std::vector<int>{-1, 0})) << text;
    EXPECT_EQ(rig.weights.rows(), 0) << text;
    EXPECT_EQ(rig.ignored_skin, strict) << text;
    const auto warnings = log.lines("warning");
    ASSERT_EQ(warnings.size(), 1u) << text;
    EXPECT_NE(warnings[0].find(strict), std::string::npos) << warnings[0];
  }
  // Skin lines that fit are kept, without a warning.
  LogCapture log;
  const Rig fits = read_rig(dir.write("fits.txt", kRig), 4, {}, SkinLines::ignore_mismatch);
  EXPECT_EQ(fits.weights.nonZeros(), 6);
  EXPECT_TRUE(fits.ignored_skin.empty());
  EXPECT_TRUE(log.lines("warning").empty());
}

TEST(RigIo, IgnoringSkinLinesLeavesSkeletonErrorsStrict) {
  TempDir dir;
  const std::string skin = "skin 7 a 1\n";  // out of range for 2 vertices: ignored
  const std::vector<std::pair<std::string, std::string>> cases = {
      {skin + "joints a 0 0\n", ":2: expected 'joints NAME x y z'"},
      {"joints a 0 0 0\njoints b 0 x 0\nroot a\nhier a b\n" + skin, ":2: bad coordinate 'x'"},
      {"joints a 0 0 0\njoints b 0 1 0\nroot a\nhier z b\n" + skin, ":4: unknown joint 'z'"},
      {"joints a 0 0 0\njoints b 0 1 0\nroot a\n" + skin, "joint 'b' has no 'hier' line"},
      {"joints a 0 0 0\njoints b 0 1 0\nroot a\nhier a b\nbone a b\n" + skin,
       ":5: unknown statement 'bone'"},
  };
  int n = 0;
  for (const auto& [text, message] : cases) {
    const auto file = dir.write("skel" + std::to_string(n++) + ".txt", text);
    expect_error<GeometryError>([&] { read_rig(file, 2, {}, SkinLines::ignore_mismatch); },
                                {file.filename().string(), message});
  }
}

TEST(RigIo, RigNetQuickStartPairsReadTheirSkeletonWithoutTheOriginalMeshsWeights) {
  // tests/data/rignet/: remeshed OBJs with the rig texts of their original meshes.
  const std::filesystem::path data = std::filesystem::path(SKINLAB_SOURCE_DIR) / "tests/data/rignet";
  EXPECT_EQ(rig_beside(data / "17872_remesh.obj"), data / "17872_ori_rig.txt");
  EXPECT_EQ(rig_beside(data / "1347_remesh.obj"), data / "1347_ori_rig.txt");
  EXPECT_TRUE(rig_beside(data / "17872_ori_rig.txt").empty());
  expect_error<GeometryError>(
      [&] { load_character(data / "17872_remesh.obj"); },
      {"17872_ori_rig.txt:16: vertex 8 is out of range (the mesh has 8 vertices)"});
  expect_error<GeometryError>([&] { load_character(data / "1347_remesh.obj"); },
                              {"1347_ori_rig.txt: vertex 6 has no weight"});
  const Character out_of_range =
      load_character(data / "17872_remesh.obj", {}, SkinLines::ignore_mismatch);
  EXPECT_EQ(out_of_range.name, "17872_remesh");
  EXPECT_EQ(out_of_range.mesh.num_vertices(), 8);
  EXPECT_EQ(out_of_range.skeleton.names, (std::vector<std::string>{"root", "mid", "top"}));
  EXPECT_FALSE(out_of_range.has_weights());
  const Character unweighted = load_character(data / "1347_remesh.obj", data / "1347_ori_rig.txt",
                                              SkinLines::ignore_mismatch);
  EXPECT_FALSE(unweighted.has_weights());
  EXPECT_EQ(unweighted.skeleton.num_joints(), 3);
}

TEST(LoadCharacter, AnObjTakesTheRigTextNextToItInADocumentedOrder) {
  TempDir dir;
  const std::string skeleton = "joints a 0 0 0\njoints b 0 1 0\nroot a\nhier a b\n";
  const auto obj = dir.write("hero.obj", kObj);
  expect_error<GeometryError>([&] { load_character(obj); },
                              {"hero.obj: an OBJ mesh has no skeleton", "hero_rig.txt, hero.txt"});
  dir.write("hero.txt", skeleton);
  EXPECT_EQ(rig_beside(obj), dir / "hero.txt");
  EXPECT_EQ(load_character(obj).skeleton.num_joints(), 2);
  dir.write("hero_rig.txt", kRig);
  EXPECT_EQ(rig_beside(obj), dir / "hero_rig.txt");
  EXPECT_EQ(load_character(obj).skeleton.num_joints(), 3);
  EXPECT_TRUE(rig_candidates(dir / "hero.fbx").empty()) << "other formats carry their skeleton";
  EXPECT_EQ(rig_candidates(dir / "7_remesh.obj").back(), dir / "7_ori_rig.txt");
  EXPECT_TRUE(is_character_file("a/b.GLB"));
  EXPECT_TRUE(is_character_file("b.obj"));
  EXPECT_FALSE(is_character_file("b_rig.txt"));
  EXPECT_FALSE(is_character_file("b.blend"));
}

TEST(RigIo, WriterRejectsUnwritableNames) {
  TempDir dir;
  Skeleton s;
  s.names = {"left arm"};
  s.positions = Eigen::MatrixXd::Zero(1, 3);
  s.parents = {-1};
  expect_error<GeometryError>([&] { write_rig(dir / "x.txt", s, {}); }, {"joint name 'left arm'"});
  EXPECT_FALSE(std::filesystem::exists(dir / "x.txt"));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

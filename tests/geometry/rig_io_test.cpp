// RigNet rig text and OBJ files: round trips and every malformed-line error with its line number.

#include <gtest/gtest.h>

#include "framework/core/atomic_file.hpp"
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

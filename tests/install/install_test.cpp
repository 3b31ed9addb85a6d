// `cmake --install` into a temporary prefix, the prefix moved elsewhere, and the installed
// `skinlab predict` run from there: the bundled model is found relative to the program, never
// through the source tree compiled into it; SKINLAB_MODEL overrides it; without either the error
// names where it looked.

#include <gtest/gtest.h>

#include <filesystem>

#include "framework/geometry/import_character.hpp"
#include "framework/geometry/obj_io.hpp"
#include "tests/cli/cli_run.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {

namespace fs = std::filesystem;
using testing::Result;
using testing::run_shell;
using testing::TempDir;

TEST(Install, AMovedPrefixPredictsWithItsOwnModel) {
  TempDir dir;
  const fs::path first = dir / "first", moved = dir / "moved", work = dir / "work";
  const Result install = run_shell(std::string("'") + SKINLAB_CMAKE + "' --install '" +
                                   SKINLAB_BINARY_DIR + "' --prefix '" + first.string() + "'");
  ASSERT_EQ(install.status, 0) << install.out << install.err;
  fs::rename(first, moved);
  const fs::path program = moved / "bin" / "skinlab";
  const fs::path model = moved / "share" / "skinlab" / "models" / "heterskinnet";
  ASSERT_TRUE(fs::is_regular_file(program));
  ASSERT_TRUE(fs::is_regular_file(model / "model.pt"));
  EXPECT_TRUE(fs::is_regular_file(moved / "share" / "skinlab" / "blender" / "skinlab_skin" / "__init__.py"));

  // A small character in a directory of its own, the program run from there.
  fs::create_directories(work);
  const fs::path bad = fs::path(SKINLAB_SOURCE_DIR) / "tests" / "data" / "bad";
  fs::copy_file(bad / "box.obj", work / "box.obj");
  fs::copy_file(bad / "box_rig.txt", work / "box_rig.txt");
  const std::string predict = "cd '" + work.string() + "' && env -u SKINLAB_MODEL '" +
                              program.string() + "' --log-level info predict box.obj --out ";

  const Result p = run_shell(predict + "box.glb");
  ASSERT_EQ(p.status, 0) << p.out << p.err;
  EXPECT_NE(p.err.find("model " + model.string() + " (installed with the program)"), std::string::npos)
      << p.err;
  EXPECT_EQ(p.err.find(SKINLAB_SOURCE_DIR), std::string::npos) << p.err;
  geometry::ImportOptions keep;
  keep.join_identical_vertices = false;
  const geometry::Character skinned = geometry::import_character(work / "box.glb", keep);
  EXPECT_EQ(skinned.mesh.num_vertices(), geometry::read_obj(work / "box.obj").num_vertices());
  EXPECT_TRUE(skinned.has_weights());

  // The program without libtorch finds the same installed model and writes the same joints.
  const fs::path small = moved / "bin" / "skinlab-predict";
  ASSERT_TRUE(fs::is_regular_file(small));
  const Result q = run_shell("cd '" + work.string() + "' && env -u SKINLAB_MODEL '" +
                             small.string() + "' --log-level info box.obj --out small.glb");
  ASSERT_EQ(q.status, 0) << q.out << q.err;
  EXPECT_NE(q.err.find("model " + model.string() + " (installed with the program)"), std::string::npos)
      << q.err;
  const geometry::Character small_skinned = geometry::import_character(work / "small.glb", keep);
  EXPECT_EQ(small_skinned.mesh.num_vertices(), skinned.mesh.num_vertices());
  EXPECT_EQ(small_skinned.skeleton.num_joints(), skinned.skeleton.num_joints());
  EXPECT_TRUE(small_skinned.has_weights());

  // SKINLAB_MODEL is taken first.
  const fs::path other = dir / "other_model";
  fs::rename(model, other);
  const Result env = run_shell("cd '" + work.string() + "' && SKINLAB_MODEL='" + other.string() +
                               "' '" + program.string() + "' --log-level info predict box.obj --out env.glb");
  ASSERT_EQ(env.status, 0) << env.out << env.err;
  EXPECT_NE(env.err.find("model " + other.string() + " (SKINLAB_MODEL)"), std::string::npos) << env.err;
  EXPECT_TRUE(fs::is_regular_file(work / "env.glb"));

  // No model anywhere: the source tree compiled in is not a fallback; the error says where it looked.
  const Result none = run_shell(predict + "none.glb");
  EXPECT_NE(none.status, 0);
  EXPECT_NE(none.err.find("no model"), std::string::npos) << none.err;
  EXPECT_NE(none.err.find(model.string()), std::string::npos) << none.err;
  EXPECT_NE(none.err.find("does not use the source tree"), std::string::npos) << none.err;
  EXPECT_FALSE(fs::exists(work / "none.glb"));

  const Result wrong = run_shell("cd '" + work.string() + "' && SKINLAB_MODEL='" + work.string() +
                                 "' '" + program.string() + "' predict box.obj --out wrong.glb");
  EXPECT_NE(wrong.status, 0);
  EXPECT_NE(wrong.err.find("SKINLAB_MODEL=" + work.string() + ": not a model directory"),
            std::string::npos)
      << wrong.err;
}

}  // namespace
}  // namespace skinlab

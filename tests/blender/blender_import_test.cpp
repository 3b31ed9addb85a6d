// The glTF that `skinlab predict` writes, imported by Blender headless (label `long`; skipped
// when `blender` is not installed: Debian's blender package, 3.4 on bookworm, needs
// python3-numpy): the armature has the character's bones, the mesh one vertex group per joint,
// and every vertex the weights we wrote (at most 4 per vertex, summing to 1).

#include <gtest/gtest.h>

#include "framework/geometry/import_character.hpp"
#include "tests/blender/blender_run.hpp"
#include "tests/cli/cli_run.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {

using testing::Result;
using testing::run;
using testing::TempDir;
using testing::value_of;

// Blender 3.4's glTF importer still uses numpy.bool, which numpy 1.24 (Debian 12) removed.
const char* kScript = R"(import numpy
if not hasattr(numpy, "bool"): numpy.bool = bool
import bpy, sys
path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=path)
arm = next(o for o in bpy.data.objects if o.type == 'ARMATURE')
mesh = next(o for o in bpy.data.objects if o.type == 'MESH')
print("BONES", len(arm.data.bones))
print("GROUPS", " ".join(sorted(g.name for g in mesh.vertex_groups)))
print("VERTICES", len(mesh.data.vertices))
worst = 0.0
most = 0
for v in mesh.data.vertices:
    w = [g.weight for g in v.groups if g.weight > 0]
    most = max(most, len(w))
    worst = max(worst, abs(sum(w) - 1.0))
print("MOST", most)
print("WORST_SUM_ERROR", worst)
)";

TEST(Blender, ImportsThePredictedGlbWithAVertexGroupPerJoint) {
  if (!testing::blender_installed()) {
    GTEST_SKIP() << "blender is not installed (apt-get install blender python3-numpy)";
  }
  TempDir dir;
  const auto horse = dir / "horse.glb", out = dir / "horse_skinned.glb";
  ASSERT_EQ(run("export configs/datasets/zeroad_bundled.yaml horse --out " + horse.string()).status, 0);
  const Result p = run("predict " + horse.string() + " --out " + out.string());
  ASSERT_EQ(p.status, 0) << p.err;
  const auto script = dir.write("check.py", kScript);
  const testing::BlenderRun blender = testing::run_blender(script.string(), "'" + out.string() + "'");
  const std::string& text = blender.text;
  ASSERT_EQ(blender.status, 0) << text;

  geometry::ImportOptions o;
  o.join_identical_vertices = false;
  const geometry::Character c = geometry::import_character(out, o);
  std::vector<std::string> names = c.skeleton.names;
  std::sort(names.begin(), names.end());
  std::string groups;
  for (const auto& n : names) groups += (groups.empty() ? "" : " ") + n;
  EXPECT_EQ(value_of(text, "BONES"), std::to_string(c.skeleton.num_joints())) << text;
  EXPECT_EQ(value_of(text, "GROUPS"), groups) << text;
  EXPECT_EQ(value_of(text, "VERTICES"), std::to_string(c.mesh.num_vertices())) << text;
  const int most = std::stoi(value_of(text, "MOST"));
  EXPECT_GE(most, 1);
  EXPECT_LE(most, 4);
  EXPECT_LT(std::stod(value_of(text, "WORST_SUM_ERROR")), 1e-4) << text;
}

}  // namespace
}  // namespace skinlab

// The Blender add-on "Skin with skinlab" (integrations/blender/skinlab_skin) end to end, Blender
// headless (label `long`; skipped when `blender` is not installed). A real character, 0 A.D.'s
// horse from the bundled subset, is built in Blender from OBJ + rig text, the add-on is installed
// from a zip and run (tests/blender/skin_addon_check.py), and every vertex group it wrote must be
// the predictor's own output on that character (`skinlab predict`) within 1e-6, with each
// vertex's weights summing to 1; "Keep" must leave existing groups as they were, and a failing
// predictor, or deform bones that form no single tree, must be reported with the message and
// change nothing.

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "framework/core/atomic_file.hpp"
#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/rig_io.hpp"
#include "tests/blender/blender_run.hpp"
#include "tests/cli/cli_run.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {

namespace fs = std::filesystem;
using testing::Result;
using testing::run;
using testing::TempDir;
using testing::value_of;

/// "group <name> <vertex> <weight>" lines of the check script: weight by (group, vertex).
std::map<std::pair<std::string, int>, double> read_groups(const fs::path& file) {
  std::map<std::pair<std::string, int>, double> groups;
  std::istringstream in(read_file(file));
  std::string word, name;
  int vertex = 0;
  double weight = 0;
  while (in >> word >> name >> vertex >> weight) groups[{name, vertex}] = weight;
  return groups;
}

/// Largest |groups(joint, v) − weights(v, joint)| over the joints in `joints` and all vertices (a
/// missing membership is weight 0), and whether every membership of those groups is a weight of
/// `weights` at all (no stray group or vertex).
double max_difference(const std::map<std::pair<std::string, int>, double>& groups,
                      const geometry::Skeleton& skeleton, const geometry::SparseWeights& weights,
                      const std::set<std::string>& joints) {
  std::map<std::pair<std::string, int>, double> expected;
  for (Eigen::Index v = 0; v < weights.outerSize(); ++v) {
    for (geometry::SparseWeights::InnerIterator it(weights, v); it; ++it) {
      if (joints.count(skeleton.names[it.col()])) {
        expected[{skeleton.names[it.col()], static_cast<int>(v)}] = it.value();
      }
    }
  }
  double worst = 0;
  for (const auto& [key, w] : expected) {
    const auto found = groups.find(key);
    worst = std::max(worst, std::abs((found == groups.end() ? 0.0 : found->second) - w));
  }
  for (const auto& [key, w] : groups) {
    if (joints.count(key.first) && !expected.count(key)) worst = std::max(worst, std::abs(w));
  }
  return worst;
}

/// Largest |Σ weights − 1| of a vertex over the groups named after a joint.
double worst_sum_error(const std::map<std::pair<std::string, int>, double>& groups,
                       const geometry::Skeleton& skeleton, int num_vertices) {
  const std::set<std::string> joints(skeleton.names.begin(), skeleton.names.end());
  std::vector<double> sums(num_vertices, 0.0);
  for (const auto& [key, w] : groups) {
    if (joints.count(key.first)) sums.at(key.second) += w;
  }
  double worst = 0;
  for (double s : sums) worst = std::max(worst, std::abs(s - 1));
  return worst;
}

TEST(BlenderAddon, VertexGroupsAreThePredictorsOwnOutput) {
  if (!testing::blender_installed()) {
    GTEST_SKIP() << "blender is not installed (apt-get install blender python3-numpy)";
  }
  TempDir dir;
  const auto exported = dir / "exported.obj";
  const Result e = run("export configs/datasets/zeroad_bundled.yaml horse --out " + exported.string());
  ASSERT_EQ(e.status, 0) << e.err;
  // Blender holds coordinates as float: the character both sides see is the export rounded to
  // float, so the predictor's reference run and the add-on start from the very same numbers.
  geometry::Character horse = geometry::read_obj_rig(exported, dir / "exported_rig.txt");
  horse.mesh.V = horse.mesh.V.cast<float>().cast<double>();
  horse.skeleton.positions = horse.skeleton.positions.cast<float>().cast<double>();
  const auto obj = dir / "horse.obj", rig = dir / "horse_rig.txt";
  geometry::write_obj(obj, horse.mesh);
  geometry::write_rig(rig, horse.skeleton, horse.weights);
  const int num_vertices = horse.mesh.num_vertices();

  const auto reference_file = dir / "reference_rig.txt";
  const Result p = run("predict " + obj.string() + " --rig " + rig.string() + " --out " +
                       reference_file.string());
  ASSERT_EQ(p.status, 0) << p.err;
  const geometry::Rig reference = geometry::read_rig(reference_file, num_vertices);
  const geometry::Skeleton& skeleton = reference.skeleton;
  const std::set<std::string> all(skeleton.names.begin(), skeleton.names.end());

  // Installed into the test's own directories, not the user's Blender configuration.
  const std::string env = "BLENDER_USER_SCRIPTS='" + (dir / "scripts").string() +
                          "' BLENDER_USER_CONFIG='" + (dir / "config").string() + "' ";
  const std::string source = SKINLAB_SOURCE_DIR;
  const testing::BlenderRun blender = testing::run_blender(
      source + "/tests/blender/skin_addon_check.py",
      "'" + source + "/integrations/blender' '" + obj.string() + "' '" + rig.string() + "' '" +
          SKINLAB_CLI + "' '" + dir.path().string() + "'",
      env);
  const std::string& text = blender.text;
  ASSERT_EQ(blender.status, 0) << text;
  EXPECT_EQ(value_of(text, "BONES"), std::to_string(skeleton.num_joints())) << text;

  // Replace: one group per bone (empty where the predictor gives the bone no weight), each the
  // predictor's weights; "mask" (no bone) as it was.
  const auto replaced = read_groups(dir / "replace.txt");
  std::set<std::string> names;
  std::istringstream group_line(value_of(text, "GROUPS"));
  for (std::string name; group_line >> name;) names.insert(name);
  std::set<std::string> expected_names = all;
  expected_names.insert("mask");
  EXPECT_EQ(names, expected_names);
  const double replace_error = max_difference(replaced, skeleton, reference.weights, all);
  EXPECT_LE(replace_error, 1e-6);
  const double sum_error = worst_sum_error(replaced, skeleton, num_vertices);
  EXPECT_LE(sum_error, 1e-6);
  int masked = 0;
  for (const auto& [key, w] : replaced) {
    if (key.first != "mask") continue;
    ++masked;
    EXPECT_EQ(key.second % 7, 0);
    EXPECT_FLOAT_EQ(w, 0.5);
  }
  EXPECT_EQ(masked, (num_vertices + 6) / 7);
  std::cout << "replace: max |group - predicted| " << replace_error << ", max |sum - 1| "
            << sum_error << " over " << num_vertices << " vertices, " << skeleton.num_joints()
            << " bones\n";

  // Keep: the groups left on the mesh are the rig's own weights, the others predicted.
  std::set<std::string> kept;
  std::istringstream kept_line(value_of(text, "KEPT"));
  for (std::string name; kept_line >> name;) kept.insert(name);
  ASSERT_FALSE(kept.empty()) << text;
  std::set<std::string> predicted;
  for (const auto& name : all) {
    if (!kept.count(name)) predicted.insert(name);
  }
  ASSERT_FALSE(predicted.empty()) << text;
  const auto keep = read_groups(dir / "keep.txt");
  EXPECT_LE(max_difference(keep, horse.skeleton, horse.weights, kept), 1e-6);
  EXPECT_LE(max_difference(keep, skeleton, reference.weights, predicted), 1e-6);

  // A predictor that fails: its message in the report, the mesh untouched.
  const std::string message = value_of(text, "ERROR_MESSAGE");
  EXPECT_NE(message.find("not a model directory"), std::string::npos) << text;
  EXPECT_NE(message.find("no_such_model"), std::string::npos) << text;
  EXPECT_EQ(value_of(text, "UNCHANGED_AFTER_ERROR"), "1") << text;

  // Deform bones that are no single tree: said before the predictor runs, nothing changed.
  const std::string deform = value_of(text, "DEFORM_ERROR");
  EXPECT_NE(deform.find("armature 'rig': the deform bones form 5 trees"), std::string::npos) << text;
  EXPECT_NE(deform.find("skinlab needs one root"), std::string::npos) << text;
  EXPECT_EQ(value_of(text, "UNCHANGED_AFTER_DEFORM_ERROR"), "1") << text;
}

}  // namespace
}  // namespace skinlab

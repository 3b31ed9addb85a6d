// `skinlab predict` as a user runs it: the bundled model on a real character and on a plain OBJ
// with rig text, and the corpus of bad inputs in tests/data/bad/ (each a one-line error naming
// the file and the element, a non-zero exit, and an existing output file left as it was);
// RigNet's quick-start pairs (tests/data/rignet/: remeshed OBJs with the rig texts of their
// original meshes); many characters in one run (--out-dir: files, a directory, a list); and a
// classical method in the network's place (--binder).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/data/h5.hpp"
#include "framework/geometry/import_character.hpp"
#include "framework/geometry/load_character.hpp"
#include "framework/geometry/rig_io.hpp"
#include "framework/infer/parameters.hpp"
#include "tests/cli/cli_run.hpp"
#include "tests/geometry/test_meshes.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using testing::Result;
using testing::run;
using testing::TempDir;

const std::string kBad = "tests/data/bad/";
const std::string kRigNet = "tests/data/rignet/";
const std::string kPlayer =
    "/usr/share/games/minetest/games/minetest_game/mods/player_api/models/character.b3d";

/// The lines of `text` that contain `marker` ("skinlab: error:" at their start when `anywhere`
/// is false).
std::vector<std::string> lines_with(const std::string& text, const std::string& marker,
                                    bool anywhere) {
  std::vector<std::string> lines;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = text.find('\n', at);
    const std::string line = text.substr(at, end == std::string::npos ? std::string::npos : end - at);
    if (anywhere ? line.find(marker) != std::string::npos : line.rfind(marker, 0) == 0) {
      lines.push_back(line);
    }
    if (end == std::string::npos) break;
    at = end + 1;
  }
  return lines;
}

/// The lines of `text` that start with "skinlab: error:".
std::vector<std::string> error_lines(const std::string& text) {
  return lines_with(text, "skinlab: error:", false);
}

/// The names of the files in `dir`, sorted.
std::vector<std::string> files_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

/// The summary row of `file` in a batch's stdout ("file  status  vertices ...").
std::string summary_row(const std::string& out, const std::string& file) {
  for (const auto& line : lines_with(out, file, false)) {
    if (line.size() > file.size() && line[file.size()] == ' ') return line;
  }
  return "";
}

struct BadCase {
  std::string args;                   ///< input [--rig ...]
  std::vector<std::string> expected;  ///< parts of the error line
};

/// `skinlab predict ARGS` or `skinlab-predict ARGS`, and the start of their error lines.
struct Program {
  std::function<Result(const std::string&)> predict;
  std::string error;
};

Program skinlab_predict() {
  return {[](const std::string& args) { return run("predict " + args); }, "skinlab: error:"};
}

Program eigen_predict() {
  return {[](const std::string& args) { return testing::run_program(SKINLAB_PREDICT_CLI, args); },
          "skinlab-predict: error:"};
}

/// Every input of the bad corpus through `program`: one error line naming the file and the
/// element, exit status 1, and the output file from an earlier run left as it was.
void expect_every_bad_input_fails(const Program& program) {
  TempDir dir;
  // A 450×450 grid: 202,500 vertices, beyond the default --max-vertices.
  {
    std::ofstream big(dir / "big.obj");
    const int n = 450;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) big << "v " << i / double(n) << " " << j / double(n) << " 0\n";
    }
    for (int j = 0; j + 1 < n; ++j) {
      for (int i = 0; i + 1 < n; ++i) {
        const int a = j * n + i + 1;
        big << "f " << a << " " << a + 1 << " " << a + n + 1 << "\nf " << a << " " << a + n + 1
            << " " << a + n << "\n";
      }
    }
  }
  const std::string big = (dir / "big.obj").string();
  const std::vector<BadCase> cases = {
      {kBad + "empty.obj --rig " + kBad + "box_rig.txt", {"empty.obj", "no vertices"}},
      {kBad + "nan_vertex.obj --rig " + kBad + "box_rig.txt",
       {"nan_vertex.obj", "vertex 6", "non-finite"}},
      {kBad + "face_out_of_range.obj --rig " + kBad + "box_rig.txt",
       {"face_out_of_range.obj:19", "vertex 9", "out of range"}},
      {kBad + "garbage.fbx", {"garbage.fbx", "assimp cannot read it"}},
      {kBad + "box.obj --rig " + kBad + "unknown_joint_rig.txt",
       {"unknown_joint_rig.txt:5", "unknown joint 'head'"}},
      {kBad + "box.obj --rig " + kBad + "cycle_rig.txt", {"cycle_rig.txt", "cycle", "'a'"}},
      {kBad + "box.obj --rig " + kBad + "two_roots_rig.txt",
       {"two_roots_rig.txt", "joint 'other'", "not the root"}},
      {kBad + "box.obj --rig " + kBad + "bone_outside_rig.txt",
       {"bone_outside_rig.txt", "joint 'far'", "outside the mesh's bounding box"}},
      {kBad + "box.obj --rig " + kBad + "units_rig.txt",
       {"units_rig.txt", "joint 'hips'", "with 3 of the 4 joints", "does not fit"}},
      {kBad + "box.obj --rig " + kBad + "zero_length_rig.txt",
       {"zero_length_rig.txt", "all 3 joints sit at one point", "zero length"}},
      {kBad + "one_vertex.obj --rig " + kBad + "one_vertex_rig.txt",
       {"one_vertex.obj", "no faces"}},
      {big + " --rig " + kBad + "box_rig.txt", {"big.obj", "202500 vertices", "--max-vertices"}},
      {kBad + "missing.obj --rig " + kBad + "box_rig.txt", {"missing.obj"}},
  };
  const fs::path out = dir / "out.glb";
  for (const BadCase& c : cases) {
    write_file_atomic(out, "a good file from an earlier run");
    const Result r = program.predict(c.args + " --out " + out.string());
    EXPECT_EQ(r.status, 1) << c.args << "\n" << r.err;
    const auto lines = lines_with(r.err, program.error, false);
    ASSERT_EQ(lines.size(), 1u) << c.args << "\n" << r.err;
    for (const auto& part : c.expected) {
      EXPECT_NE(lines[0].find(part), std::string::npos) << c.args << ": '" << part << "' not in\n"
                                                        << lines[0];
    }
    EXPECT_EQ(read_file(out), "a good file from an earlier run") << c.args;
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 2)
        << c.args << ": a stray file was left";
  }
}

TEST(PredictCli, EveryBadInputIsAOneLineErrorAndLeavesTheOutputAlone) {
  expect_every_bad_input_fails(skinlab_predict());
}

TEST(EigenPredictCli, EveryBadInputIsAOneLineErrorAndLeavesTheOutputAlone) {
  expect_every_bad_input_fails(eigen_predict());
}

/// An IK pole target (a chain of two joints) far outside the box: left out with a warning naming
/// it; every output still lists every input joint, the left-out ones with no weight, and the
/// other joints' weights are those of the rig without them.
void expect_helper_ends_left_out(const Program& program) {
  TempDir dir;
  const fs::path glb = dir / "pole.glb", h5 = dir / "pole.h5", rig = dir / "pole_rig.txt";
  const Result r = program.predict(kBad + "box.obj --rig " + kBad + "box_pole_target_rig.txt" +
                                   " --out " + glb.string() + " --out " + h5.string() + " --out " +
                                   rig.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("'knee_pole', 'knee_pole_end' outside the mesh at the end of the skeleton, "
                       "left out of the prediction with weight 0"),
            std::string::npos)
      << r.err;
  const data::H5Reader file(h5);
  EXPECT_EQ(file.read_strings("joint_names"),
            (std::vector<std::string>{"root", "mid", "top", "knee_pole", "knee_pole_end"}));
  const data::RowMatrixXd joint = file.read_double("joint_weights");
  ASSERT_EQ(joint.cols(), 5);
  EXPECT_EQ(joint.rightCols(2).cwiseAbs().maxCoeff(), 0.0);
  for (Eigen::Index v = 0; v < joint.rows(); ++v) EXPECT_NEAR(joint.row(v).sum(), 1.0, 1e-5);
  const data::RowMatrixXi bones = file.read_int("bones");
  EXPECT_LT(bones.maxCoeff(), 3) << "no bone reaches a left-out joint";
  const geometry::Rig text = geometry::read_rig(rig, 8);
  EXPECT_EQ(text.skeleton.names, file.read_strings("joint_names"));
  EXPECT_LT((Eigen::MatrixXd(text.weights) - Eigen::MatrixXd(joint)).cwiseAbs().maxCoeff(), 1e-6);
  geometry::ImportOptions o;
  o.join_identical_vertices = false;
  EXPECT_EQ(geometry::import_character(glb, o).skeleton.num_joints(), 5);

  // The same weights as the rig without the pole target.
  const fs::path plain = dir / "plain.h5";
  const Result p = program.predict(kBad + "box.obj --rig " + kBad + "box_rig.txt --out " +
                                   plain.string());
  ASSERT_EQ(p.status, 0) << p.err;
  EXPECT_LT((data::H5Reader(plain).read_double("joint_weights") - joint.leftCols(3))
                .cwiseAbs()
                .maxCoeff(),
            1e-6);
}

TEST(PredictCli, HelperEndsOutsideTheMeshAreLeftOutWithAWarning) {
  expect_helper_ends_left_out(skinlab_predict());
}

// An artist's rig with an IK pole target far outside the mesh is scored on the skeleton a
// prediction skins (it was refused as a rig that does not fit).
TEST(PredictCli, ScoreLeavesHelperEndsOutsideTheMeshOut) {
  TempDir dir;
  std::string text = read_file(fs::path(SKINLAB_SOURCE_DIR) / kBad / "box_pole_target_rig.txt");
  for (int v = 0; v < 8; ++v) text += "skin " + std::to_string(v) + (v < 4 ? " root 1\n" : " mid 1\n");
  const fs::path truth = dir / "truth_rig.txt";
  write_file_atomic(truth, text);
  const Result self =
      run("score " + kBad + "box.obj --rig " + truth.string() + " --weights " + truth.string());
  ASSERT_EQ(self.status, 0) << self.err;
  EXPECT_NE(self.out.find("precision 1.0000"), std::string::npos) << self.out;
}

TEST(EigenPredictCli, HelperEndsOutsideTheMeshAreLeftOutWithAWarning) {
  expect_helper_ends_left_out(eigen_predict());
}

TEST(PredictCli, UsageErrorsComeBeforeAnyWork) {
  TempDir dir;
  const Result ext = run("predict " + kBad + "box.obj --rig " + kBad + "box_rig.txt --out " +
                         (dir / "w.fbx").string());
  EXPECT_EQ(ext.status, 1);
  EXPECT_NE(ext.err.find("unknown output type '.fbx'"), std::string::npos) << ext.err;
  const Result model = run("predict " + kBad + "box.obj --rig " + kBad + "box_rig.txt --model " +
                           (dir / "nomodel").string() + " --out " + (dir / "w.glb").string());
  EXPECT_EQ(model.status, 1);
  EXPECT_NE(model.err.find("not a model directory"), std::string::npos) << model.err;
  const Result compare = run("predict " + kBad + "box.obj --rig " + kBad +
                             "box_rig.txt --compare-to-input --out " + (dir / "w.glb").string());
  EXPECT_EQ(compare.status, 1);
  EXPECT_NE(compare.err.find("carries no skin weights"), std::string::npos) << compare.err;
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(PredictCli, BundledModelSkinsARealCharacterAndAPlainObj) {
  TempDir dir;
  const fs::path glb = dir / "player.glb", rig = dir / "player_rig.txt", h5 = dir / "player.h5";
  const Result r = run("predict " + kPlayer + " --compare-to-input --timings --out " +
                       glb.string() + " --out " + rig.string() + " --out " + h5.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("against the input's weights: avg_l1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("stages (s): load"), std::string::npos) << r.out;

  const geometry::Character input = geometry::import_character(kPlayer);
  geometry::ImportOptions o;
  o.join_identical_vertices = false;
  const geometry::Character back = geometry::import_character(glb, o);
  EXPECT_EQ(back.skeleton.names, input.skeleton.names);
  EXPECT_EQ(back.skeleton.parents, input.skeleton.parents);
  EXPECT_EQ(back.mesh.num_vertices(), input.mesh.num_vertices());
  // The rig text and the HDF5 file carry the same per-joint weights; the glTF their top 4.
  const geometry::Rig text = geometry::read_rig(rig, input.mesh.num_vertices());
  const data::H5Reader file(h5);
  const data::RowMatrixXd joint = file.read_double("joint_weights");
  ASSERT_EQ(joint.rows(), input.mesh.num_vertices());
  EXPECT_LT((Eigen::MatrixXd(text.weights) - Eigen::MatrixXd(joint)).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((Eigen::MatrixXd(back.weights) - Eigen::MatrixXd(joint)).cwiseAbs().maxCoeff(), 1e-6)
      << "the player's vertices have at most 4 influences after pruning";
  EXPECT_EQ(file.read_strings("joint_names"), input.skeleton.names);

  const Result obj = run("predict " + kBad + "box.obj --rig " + kBad + "box_rig.txt --out " +
                         (dir / "box.gltf").string());
  ASSERT_EQ(obj.status, 0) << obj.err;
  const geometry::Character box = geometry::import_character(dir / "box.gltf", o);
  EXPECT_EQ(box.skeleton.names, (std::vector<std::string>{"root", "mid", "top"}));
  EXPECT_EQ(box.mesh.num_vertices(), 8);
}

// --binder: a classical method on the model's preparation, pruned and mapped back alike; its
// weights are bone heat's, not the network's, and a bad binder is an error before any work.
TEST(PredictCli, BinderSkinsTheCharacterInsteadOfTheNetwork) {
  TempDir dir;
  const fs::path heat = dir / "heat_rig.txt", joints = dir / "joints_rig.txt",
                 file = dir / "file_rig.txt", net = dir / "net_rig.txt";
  const Result r = run("predict " + kPlayer + " --binder bone_heat --compare-to-input --out " +
                       heat.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("against the input's weights: avg_l1"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("binder 'bone_heat' on the preparation of"), std::string::npos) << r.err;
  ASSERT_EQ(run("predict " + kPlayer + " --binder '{type: bone_heat, heat_sources: joints}' "
                "--out " + joints.string()).status, 0);
  ASSERT_EQ(run("predict " + kPlayer + " --binder configs/baselines/bone_heat.yaml --out " +
                file.string()).status, 0);
  ASSERT_EQ(run("predict " + kPlayer + " --out " + net.string()).status, 0);
  const geometry::Character input = geometry::import_character(kPlayer);
  const int nv = input.mesh.num_vertices();
  const Eigen::MatrixXd W(geometry::read_rig(heat, nv).weights);
  ASSERT_EQ(W.cols(), input.skeleton.num_joints());
  for (int v = 0; v < nv; ++v) ASSERT_NEAR(W.row(v).sum(), 1.0, 1e-5) << "vertex " << v;
  // The config file names bone heat with the options of configs/baselines/bone_heat.yaml.
  const Eigen::MatrixXd from_file(geometry::read_rig(file, nv).weights);
  const double to_joints = (Eigen::MatrixXd(geometry::read_rig(joints, nv).weights) - W)
                               .cwiseAbs().maxCoeff();
  const double to_file = (from_file - W).cwiseAbs().maxCoeff();
  const double to_network = (Eigen::MatrixXd(geometry::read_rig(net, nv).weights) - W)
                                .cwiseAbs().maxCoeff();
  EXPECT_LT(to_file, 1e-6);
  EXPECT_GT(to_joints, 0.1) << "the player's body joint has three children";
  EXPECT_GT(to_network, 0.1);

  const std::string out = " --out " + (dir / "bad.glb").string();
  const std::vector<std::pair<std::string, std::vector<std::string>>> bad = {
      {"nonsense", {"unknown binder type 'nonsense'", "bone_heat"}},
      {"artist_weights", {"'artist_weights' is a reference row"}},
      {"'{type: bone_heat, closest: nearest}'", {"closest", "must be 'visible' or 'blender'"}},
      {"'{closest: blender}'", {"binder"}},
      {"configs/base.yaml", {"configs/base.yaml", "no binder: section"}}};
  for (const auto& [spec, words] : bad) {
    const Result e = run("predict " + kPlayer + " --binder " + spec + out);
    EXPECT_EQ(e.status, 1) << spec;
    ASSERT_EQ(error_lines(e.err).size(), 1u) << spec << ": " << e.err;
    for (const auto& w : words) EXPECT_NE(e.err.find(w), std::string::npos) << spec << ": " << e.err;
  }
  EXPECT_FALSE(fs::exists(dir / "bad.glb"));
}

TEST(PredictCli, GameCharacterExportedFromItsSourceIsSkinnedAndRendered) {
  // A real 0 A.D. character of the bundled subset, exported from its PMD with the artist's
  // weights, then skinned by the bundled model and compared with those weights.
  TempDir dir;
  const fs::path horse = dir / "horse.glb";
  const Result e = run("export configs/datasets/zeroad_bundled.yaml horse --out " + horse.string());
  ASSERT_EQ(e.status, 0) << e.err;
  EXPECT_NE(e.out.find("horse (zeroad: art/meshes/skeletal/horse.dae.cached.pmd)"),
            std::string::npos)
      << e.out;
  geometry::ImportOptions o;
  o.join_identical_vertices = false;
  const geometry::Character artist = geometry::import_character(horse, o);
  // 0 A.D.'s frame is left-handed: the export mirrors it, so the horse faces +Z as glTF assets
  // do, its left legs are on its left (+X when facing +Z) and its faces point outwards.
  const auto joint = [&](const geometry::Character& c, const std::string& name) {
    const int j = c.skeleton.find(name);
    EXPECT_GE(j, 0) << name;
    return Eigen::Vector3d(c.skeleton.positions.row(std::max(j, 0)));
  };
  EXPECT_GT(joint(artist, "head").z(), joint(artist, "tail").z());
  EXPECT_GT(joint(artist, "l_hoof").x(), 0);
  EXPECT_LT(joint(artist, "r_hoof").x(), 0);
  EXPECT_GT(testing::signed_volume(artist.mesh.V, artist.mesh.F), 0);
  // The OBJ + rig export is the same character, mirrored the same way.
  const Result obj = run("export configs/datasets/zeroad_bundled.yaml horse --out " +
                         (dir / "horse.obj").string());
  ASSERT_EQ(obj.status, 0) << obj.err;
  const geometry::Character rigged =
      geometry::read_obj_rig(dir / "horse.obj", dir / "horse_rig.txt");
  EXPECT_GT(joint(rigged, "l_hoof").x(), 0);
  EXPECT_GT(joint(rigged, "head").z(), joint(rigged, "tail").z());
  EXPECT_GT(testing::signed_volume(rigged.mesh.V, rigged.mesh.F), 0);

  const fs::path out = dir / "horse_skinned.glb", png = dir / "horse.png";
  const Result r = run("predict " + horse.string() + " --compare-to-input --out " + out.string() +
                       " --render " + png.string() + " --error-map");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto at = r.out.find("precision ");
  ASSERT_NE(at, std::string::npos) << r.out;
  const double precision = std::stod(r.out.substr(at + 10));
  EXPECT_GT(precision, 0.3) << r.out;  // a trained model, not a random one
  const geometry::Character skinned = geometry::import_character(out, o);
  EXPECT_EQ(skinned.skeleton.names, artist.skeleton.names);
  EXPECT_EQ(skinned.mesh.num_vertices(), artist.mesh.num_vertices());
  EXPECT_LT((skinned.skeleton.positions - artist.skeleton.positions).cwiseAbs().maxCoeff(), 1e-5);
  const std::string image = read_file(png);
  ASSERT_GT(image.size(), 8u);
  EXPECT_EQ(image.substr(1, 3), "PNG");

  // skinlab score: the artist's weights scored against themselves lose only what the 0.25
  // pruning of every scored method removes (precision 1); a file of another mesh is refused.
  const Result self = run("score " + horse.string() + " --weights " + horse.string());
  ASSERT_EQ(self.status, 0) << self.err;
  EXPECT_NE(self.out.find("precision 1.0000"), std::string::npos) << self.out;
  const Result other = run("score " + horse.string() + " --weights " + kPlayer);
  EXPECT_EQ(other.status, 1);
  EXPECT_NE(other.err.find("vertices, but"), std::string::npos) << other.err;
  // A method that leaves a vertex without weight (Blender's automatic weights do): refused,
  // or with --allow-unweighted scored as predicting no bone, and said so.
  const fs::path holed = dir / "holed_rig.txt";
  geometry::write_rig(holed, artist.skeleton, artist.weights);
  std::string text = read_file(holed);
  const auto line = text.find("\nskin 0 ");
  ASSERT_NE(line, std::string::npos);
  text.erase(line, text.find('\n', line + 1) - line);
  write_file_atomic(holed, text);
  const Result refused = run("score " + horse.string() + " --weights " + holed.string());
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("vertex 0 has no weight"), std::string::npos) << refused.err;
  const Result allowed =
      run("score " + horse.string() + " --allow-unweighted --weights " + holed.string());
  ASSERT_EQ(allowed.status, 0) << allowed.err;
  EXPECT_NE(allowed.out.find("1 of " + std::to_string(artist.mesh.num_vertices()) +
                             " vertices have no weight"),
            std::string::npos)
      << allowed.out;
  // No skin line at all: with --allow-unweighted every vertex predicts no bone (recall 0).
  const fs::path bare = dir / "bare_rig.txt";
  geometry::write_rig(bare, artist.skeleton, {});
  const Result none = run("score " + horse.string() + " --allow-unweighted --weights " + bare.string());
  ASSERT_EQ(none.status, 0) << none.err;
  EXPECT_NE(none.out.find(std::to_string(artist.mesh.num_vertices()) + " of " +
                          std::to_string(artist.mesh.num_vertices()) + " vertices have no weight"),
            std::string::npos)
      << none.out;
  EXPECT_NE(none.out.find("recall 0.0000"), std::string::npos) << none.out;
  const Result bare_refused = run("score " + horse.string() + " --weights " + bare.string());
  EXPECT_EQ(bare_refused.status, 1);

  const Result missing = run("export configs/datasets/zeroad_bundled.yaml unicorn --out " +
                             (dir / "u.glb").string());
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find("no character 'unicorn'"), std::string::npos) << missing.err;
  EXPECT_FALSE(fs::exists(dir / "u.glb"));

  // Many characters in one reading of the sources: each as DIR/<name>.<format>; one unknown
  // name among them writes nothing and names it.
  const fs::path many = dir / "many";
  const Result bad = run("export configs/datasets/zeroad_bundled.yaml goat unicorn --out-dir " +
                         many.string());
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("no character 'unicorn'"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("nothing written"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(many));
  const Result both = run("export configs/datasets/zeroad_bundled.yaml goat horse --out-dir " +
                          many.string() + " --format obj");
  ASSERT_EQ(both.status, 0) << both.err;
  for (const std::string name : {"goat", "horse"}) {
    EXPECT_TRUE(fs::exists(many / (name + ".obj"))) << name;
    EXPECT_TRUE(fs::exists(many / (name + "_rig.txt"))) << name;
  }
  // The horse written as OBJ + rig is the horse written as glTF: same skeleton and vertices.
  const geometry::Character from_obj =
      geometry::load_character(many / "horse.obj", many / "horse_rig.txt");
  EXPECT_EQ(from_obj.skeleton.names, artist.skeleton.names);
  EXPECT_EQ(from_obj.mesh.num_vertices(), artist.mesh.num_vertices());
  const Result two_to_one = run("export configs/datasets/zeroad_bundled.yaml goat horse --out " +
                                (dir / "two.glb").string());
  EXPECT_EQ(two_to_one.status, 1);
  EXPECT_NE(two_to_one.err.find("--out names one file"), std::string::npos) << two_to_one.err;
  EXPECT_FALSE(fs::exists(dir / "two.glb"));
}

TEST(PredictCli, RigNetQuickStartPairIsPredictedWithOneWarningAboutItsSkinLines) {
  TempDir dir;
  // With --rig: the skin lines reference vertices beyond the 8 of the remeshed mesh.
  const fs::path glb = dir / "17872.glb";
  const Result r = run("predict " + kRigNet + "17872_remesh.obj --rig " + kRigNet +
                       "17872_ori_rig.txt --out " + glb.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(glb));
  geometry::ImportOptions o;
  o.join_identical_vertices = false;
  const geometry::Character skinned = geometry::import_character(glb, o);
  EXPECT_EQ(skinned.mesh.num_vertices(), 8);
  EXPECT_EQ(skinned.skeleton.names, (std::vector<std::string>{"root", "mid", "top"}));
  const auto warnings = lines_with(r.err, "[warning]", true);
  ASSERT_EQ(warnings.size(), 1u) << r.err;
  EXPECT_NE(warnings[0].find("17872_ori_rig.txt:16: vertex 8 is out of range (the mesh has 8 "
                             "vertices)"),
            std::string::npos)
      << warnings[0];
  EXPECT_TRUE(error_lines(r.err).empty()) << r.err;

  // Without --rig: the OBJ takes <id>_ori_rig.txt, which leaves vertex 6 without weight.
  const fs::path rig = dir / "1347_rig.txt";
  const Result beside = run("predict " + kRigNet + "1347_remesh.obj --out " + rig.string());
  ASSERT_EQ(beside.status, 0) << beside.err;
  EXPECT_EQ(geometry::read_rig(rig, 8).weights.rows(), 8) << "every vertex predicted";
  const auto beside_warnings = lines_with(beside.err, "[warning]", true);
  ASSERT_EQ(beside_warnings.size(), 1u) << beside.err;
  EXPECT_NE(beside_warnings[0].find("1347_ori_rig.txt: vertex 6 has no weight"), std::string::npos)
      << beside_warnings[0];

  // Comparing and scoring need the skin lines: today's precise errors, nothing written.
  const std::string pair = kRigNet + "17872_remesh.obj --rig " + kRigNet + "17872_ori_rig.txt";
  const std::string precise = "17872_ori_rig.txt:16: vertex 8 is out of range (the mesh has 8 vertices)";
  for (const std::string& args :
       {"predict " + pair + " --compare-to-input --out " + (dir / "c.glb").string(),
        "predict " + pair + " --render " + (dir / "c.png").string() + " --error-map",
        "score " + pair + " --weights " + kRigNet + "17872_ori_rig.txt"}) {
    const Result refused = run(args);
    EXPECT_EQ(refused.status, 1) << args;
    const auto lines = error_lines(refused.err);
    ASSERT_EQ(lines.size(), 1u) << args << "\n" << refused.err;
    EXPECT_NE(lines[0].find(precise), std::string::npos) << args << "\n" << lines[0];
  }
  const Result unweighted = run("predict " + kRigNet + "1347_remesh.obj --compare-to-input --out " +
                                (dir / "u.glb").string());
  EXPECT_EQ(unweighted.status, 1);
  EXPECT_NE(unweighted.err.find("1347_ori_rig.txt: vertex 6 has no weight"), std::string::npos)
      << unweighted.err;
  EXPECT_FALSE(fs::exists(dir / "c.glb"));
  EXPECT_FALSE(fs::exists(dir / "c.png"));
  EXPECT_FALSE(fs::exists(dir / "u.glb"));

  // A broken joint line is still an error naming the file and the line.
  std::string text = read_file(fs::path(SKINLAB_SOURCE_DIR) / kRigNet / "17872_ori_rig.txt");
  const std::string joint = "joints mid 0 0.5 0";
  ASSERT_NE(text.find(joint), std::string::npos);
  text.replace(text.find(joint), joint.size(), "joints mid 0 half 0");
  const fs::path broken = dir / "broken_rig.txt";
  write_file_atomic(broken, text);
  const Result bad = run("predict " + kRigNet + "17872_remesh.obj --rig " + broken.string() +
                         " --out " + (dir / "b.glb").string());
  EXPECT_EQ(bad.status, 1);
  const auto bad_lines = error_lines(bad.err);
  ASSERT_EQ(bad_lines.size(), 1u) << bad.err;
  EXPECT_NE(bad_lines[0].find("broken_rig.txt:4: bad coordinate 'half'"), std::string::npos)
      << bad_lines[0];
  EXPECT_FALSE(fs::exists(dir / "b.glb"));
}

TEST(PredictCli, BatchWritesTheGoodCharactersSkipsTheBadOnesAndSaysWhich) {
  TempDir dir;
  // A character whose joint lies far outside its mesh: it loads, then fails its check.
  fs::copy_file(fs::path(SKINLAB_SOURCE_DIR) / kBad / "box.obj", dir / "far.obj");
  fs::copy_file(fs::path(SKINLAB_SOURCE_DIR) / kBad / "bone_outside_rig.txt", dir / "far_rig.txt");
  const std::string far = (dir / "far.obj").string();
  const fs::path out = dir / "out";
  const Result r = run("predict " + kBad + "box.obj " + kBad + "garbage.fbx " + kPlayer + " " +
                       far + " " + kRigNet + "1347_remesh.obj --out-dir " + out.string());
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(files_in(out), (std::vector<std::string>{"1347_remesh.glb", "box.glb", "character.glb"}))
      << "the good ones written, nothing for the bad ones, no temporary file left";
  const geometry::Character box = geometry::import_character(out / "box.glb");
  EXPECT_EQ(box.skeleton.names, (std::vector<std::string>{"root", "mid", "top"}));

  // One line per bad file, naming it and the reason; then the run's own error.
  const auto skipped = lines_with(r.err, "(skipped)", true);
  ASSERT_EQ(skipped.size(), 2u) << r.err;
  EXPECT_NE(skipped[0].find("garbage.fbx"), std::string::npos) << skipped[0];
  EXPECT_NE(skipped[0].find("assimp cannot read it"), std::string::npos) << skipped[0];
  EXPECT_NE(skipped[1].find("far.obj with " + (dir / "far_rig.txt").string()), std::string::npos)
      << skipped[1];
  EXPECT_NE(skipped[1].find("outside the mesh's bounding box"), std::string::npos) << skipped[1];
  const auto errors = error_lines(r.err);
  ASSERT_EQ(errors.size(), 1u) << r.err;
  EXPECT_NE(errors[0].find("2 of 5 characters failed"), std::string::npos) << errors[0];

  // The summary: every input with its status, counts and time.
  EXPECT_NE(r.out.find("3 of 5 characters written to " + out.string()), std::string::npos) << r.out;
  const std::string box_row = summary_row(r.out, kBad + "box.obj");
  EXPECT_NE(box_row.find(" ok "), std::string::npos) << r.out;
  EXPECT_NE(box_row.find(" 8 "), std::string::npos) << box_row;  // vertices
  EXPECT_NE(summary_row(r.out, kPlayer).find(" ok "), std::string::npos) << r.out;
  EXPECT_NE(summary_row(r.out, kRigNet + "1347_remesh.obj").find(" ok "), std::string::npos) << r.out;
  EXPECT_NE(summary_row(r.out, kBad + "garbage.fbx").find(" failed "), std::string::npos) << r.out;
  EXPECT_NE(summary_row(r.out, far).find(" failed "), std::string::npos) << r.out;
}

TEST(PredictCli, BatchTakesADirectoryAndAListFile) {
  TempDir dir;
  // A directory: its character files, sorted; the rig texts beside the OBJs are theirs.
  const fs::path rigs = dir / "rigs";
  const Result d = run("predict " + kRigNet + " --out-dir " + rigs.string() + " --format rig");
  ASSERT_EQ(d.status, 0) << d.err;
  EXPECT_EQ(files_in(rigs), (std::vector<std::string>{"1347_remesh_rig.txt", "17872_remesh_rig.txt"}));
  EXPECT_EQ(geometry::read_rig(rigs / "17872_remesh_rig.txt", 8).weights.rows(), 8);
  const std::string first = summary_row(d.out, kRigNet + "1347_remesh.obj");
  const std::string second = summary_row(d.out, kRigNet + "17872_remesh.obj");
  EXPECT_NE(first.find(" ok "), std::string::npos) << d.out;
  EXPECT_NE(second.find(" ok "), std::string::npos) << d.out;
  EXPECT_LT(d.out.find(first), d.out.find(second)) << "sorted by name\n" << d.out;
  EXPECT_EQ(lines_with(d.err, "[warning]", true).size(), 2u) << "one per rig text\n" << d.err;

  // A list: paths relative to the list file, comments and blank lines skipped.
  fs::create_directories(dir / "chars");
  fs::copy_file(fs::path(SKINLAB_SOURCE_DIR) / kBad / "box.obj", dir / "chars" / "crate.obj");
  fs::copy_file(fs::path(SKINLAB_SOURCE_DIR) / kBad / "box_rig.txt", dir / "chars" / "crate_rig.txt");
  const fs::path list = dir / "list.txt";
  write_file_atomic(list, "# characters to skin\nchars/crate.obj\n\n  " + kPlayer + "  \n");
  const fs::path h5 = dir / "h5";
  const Result l = run("predict @" + list.string() + " --out-dir " + h5.string() + " --format h5");
  ASSERT_EQ(l.status, 0) << l.err;
  EXPECT_EQ(files_in(h5), (std::vector<std::string>{"character.h5", "crate.h5"}));
  EXPECT_EQ(data::H5Reader(h5 / "crate.h5").read_double("joint_weights").rows(), 8);
  EXPECT_NE(l.out.find("2 of 2 characters written"), std::string::npos) << l.out;
}

TEST(PredictCli, BatchUsageErrorsComeBeforeAnyWork) {
  TempDir dir;
  fs::copy_file(fs::path(SKINLAB_SOURCE_DIR) / kBad / "box.obj", dir / "box.obj");
  fs::copy_file(fs::path(SKINLAB_SOURCE_DIR) / kBad / "box_rig.txt", dir / "box_rig.txt");
  write_file_atomic(dir / "hero.glb", "an input the batch must not overwrite");
  fs::create_directories(dir / "textures");
  write_file_atomic(dir / "textures" / "skin.png", "not a character");
  const fs::path out = dir / "out";
  struct Case {
    std::string args;
    std::string message;
  };
  // A model that does not exist: every one of these errors must come before it is loaded.
  const std::string model = " --model " + (dir / "nomodel").string();
  const std::vector<Case> cases = {
      {kBad + "box.obj " + (dir / "box.obj").string() + " --out-dir " + out.string(),
       "predict: tests/data/bad/box.obj and " + (dir / "box.obj").string() +
           " would both write " + (out / "box.glb").string()},
      {(dir / "hero.glb").string() + " --out-dir " + dir.path().string(),
       "would replace the input " + (dir / "hero.glb").string()},
      {kBad + "box.obj " + kPlayer + " --out " + (dir / "x.glb").string(),
       "2 inputs need --out-dir DIR"},
      {kBad + "box.obj --out " + (dir / "x.glb").string() + " --out-dir " + out.string(),
       "--out is for one input"},
      {kRigNet + " --out " + (dir / "x.glb").string(), "a directory or list of characters needs --out-dir"},
      {"@" + (dir / "absent.txt").string() + " --out-dir " + out.string(), "absent.txt"},
      {(dir / "textures").string() + " --out-dir " + out.string(),
       "textures: a directory without character files"},
      {kBad + "box.obj --rig " + kBad + "box_rig.txt --out-dir " + out.string(),
       "--rig goes with one OBJ input"},
      {kBad + "box.obj --out-dir " + out.string() + " --render " + (dir / "x.png").string(),
       "--render and --error-map draw one character"},
  };
  const auto before = files_in(dir.path());
  for (const Case& c : cases) {
    const Result r = run("predict " + c.args + model);
    EXPECT_EQ(r.status, 1) << c.args << "\n" << r.err;
    const auto lines = error_lines(r.err);
    ASSERT_EQ(lines.size(), 1u) << c.args << "\n" << r.err;
    EXPECT_NE(lines[0].find(c.message), std::string::npos) << c.args << "\n" << lines[0];
    EXPECT_EQ(lines[0].find("not a model directory"), std::string::npos) << lines[0];
    EXPECT_EQ(files_in(dir.path()), before) << c.args << ": something was written";
  }
  EXPECT_EQ(read_file(dir / "hero.glb"), "an input the batch must not overwrite");
}

/// Max abs difference of the dataset `name` of two .h5 predictions.
double h5_difference(const fs::path& a, const fs::path& b, const std::string& name) {
  const data::RowMatrixXd x = data::H5Reader(a).read_double(name);
  const data::RowMatrixXd y = data::H5Reader(b).read_double(name);
  EXPECT_EQ(x.rows(), y.rows()) << name;
  EXPECT_EQ(x.cols(), y.cols()) << name;
  if (x.rows() != y.rows() || x.cols() != y.cols()) return 1e30;
  return (x - y).cwiseAbs().maxCoeff();
}

TEST(EigenPredictCli, WritesWhatSkinlabPredictWritesOneFileAndBatch) {
  TempDir dir;
  const std::vector<std::string> inputs = {kPlayer, kBad + "box.obj --rig " + kBad + "box_rig.txt"};
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const fs::path torch = dir / ("torch" + std::to_string(k) + ".h5");
    const fs::path eigen = dir / ("eigen" + std::to_string(k) + ".h5");
    const fs::path glb = dir / ("eigen" + std::to_string(k) + ".glb");
    const Result t = run("predict " + inputs[k] + " --out " + torch.string());
    ASSERT_EQ(t.status, 0) << t.err;
    const Result e = testing::run_program(
        SKINLAB_PREDICT_CLI, inputs[k] + " --timings --out " + eigen.string() + " --out " + glb.string());
    ASSERT_EQ(e.status, 0) << e.err;
    EXPECT_NE(e.out.find("stages (s): load"), std::string::npos) << e.out;
    EXPECT_LE(h5_difference(torch, eigen, "weights"), 1e-5) << inputs[k];
    EXPECT_LE(h5_difference(torch, eigen, "joint_weights"), 1e-5) << inputs[k];
    EXPECT_EQ(data::H5Reader(torch).read_strings("joint_names"),
              data::H5Reader(eigen).read_strings("joint_names"));
    EXPECT_EQ(data::H5Reader(eigen).read_attribute("/", "distance"), "hollow_dist");
    geometry::ImportOptions o;
    o.join_identical_vertices = false;
    const geometry::Character back = geometry::import_character(glb, o);
    EXPECT_EQ(back.mesh.num_vertices(), data::H5Reader(eigen).read_double("weights").rows());
  }

  // Many inputs, one model load: the same summary and files as skinlab predict's.
  const fs::path out = dir / "batch";
  const Result b = testing::run_program(
      SKINLAB_PREDICT_CLI, kPlayer + " " + kBad + "garbage.fbx " + kRigNet + " --out-dir " +
                               out.string() + " --format rig");
  EXPECT_EQ(b.status, 1) << b.err;
  EXPECT_EQ(files_in(out), (std::vector<std::string>{"1347_remesh_rig.txt", "17872_remesh_rig.txt",
                                                     "character_rig.txt"}));
  EXPECT_NE(b.out.find("3 of 4 characters written to " + out.string()), std::string::npos) << b.out;
  const auto errors = lines_with(b.err, "skinlab-predict: error:", false);
  ASSERT_EQ(errors.size(), 1u) << b.err;
  EXPECT_NE(errors[0].find("1 of 4 characters failed: " + kBad + "garbage.fbx"), std::string::npos)
      << errors[0];
}

TEST(EigenPredictCli, BadParameterFileIsAnErrorNamingTheFileAndTheElement) {
  TempDir dir;
  const fs::path bundled = fs::path(SKINLAB_SOURCE_DIR) / "results" / "bundled" / "heterskinnet";
  const infer::ParameterFile good = infer::read_parameter_file(bundled / "parameters.h5");
  const fs::path model = dir / "model";
  fs::create_directories(model);
  for (const char* f : {"config.yaml", "preparation.yaml"}) fs::copy_file(bundled / f, model / f);
  const fs::path file = model / "parameters.h5";
  const fs::path out = dir / "out.glb";

  struct Case {
    std::string what;
    std::function<void()> write;  ///< writes the bad parameters.h5 (or none)
    std::vector<std::string> expected;
  };
  const auto with = [&](const std::function<void(infer::ParameterFile&)>& change) {
    return [&, change] {
      infer::ParameterFile p = good;
      change(p);
      infer::write_parameter_file(file, p);
    };
  };
  const std::vector<Case> cases = {
      {"missing", [] {}, {file.string(), "missing", "skinlab export-parameters"}},
      {"garbage", [&] { write_file_atomic(file, "not an HDF5 file"); }, {file.string()}},
      {"a NaN",
       with([](infer::ParameterFile& p) {
         p.parameters.at("head.linear0.weight").values[5] = std::nanf("");
       }),
       {file.string(), "parameter 'head.linear0.weight'", "element 5"}},
      {"a missing parameter",
       with([](infer::ParameterFile& p) { p.parameters.erase("stem.0_b2v.mlp.linear0.bias"); }),
       {file.string(), "no parameter 'stem.0_b2v.mlp.linear0.bias'"}},
      {"a wrong shape",
       with([](infer::ParameterFile& p) {
         auto& w = p.parameters.at("head.linear1.weight");
         w.shape = {w.shape[1], w.shape[0]};
       }),
       {file.string(), "parameter 'head.linear1.weight' has shape [1024, 512], expected [512, 1024]"}},
      {"an extra parameter",
       with([](infer::ParameterFile& p) { p.parameters["spare.weight"] = {{1}, {0.5f}}; }),
       {file.string(), "parameter 'spare.weight' is not used"}},
      {"an op the Eigen pass lacks",
       with([](infer::ParameterFile& p) { p.architecture["local"][2]["type"] = "gat_block"; }),
       {file.string(), "op 'local.2_mesh_conv' (type gat_block) is not implemented"}},
      {"another model",
       with([](infer::ParameterFile& p) { p.model = "rignet_skin"; }),
       {file.string(), "model 'rignet_skin' is not implemented"}},
      {"a missing architecture field",
       with([](infer::ParameterFile& p) { p.architecture.erase("top_k"); }),
       {file.string(), "architecture", "'top_k'"}},
  };
  for (const Case& c : cases) {
    fs::remove(file);
    c.write();
    const Result r = testing::run_program(SKINLAB_PREDICT_CLI, kBad + "box.obj --rig " + kBad +
                                                                   "box_rig.txt --model " +
                                                                   model.string() + " --out " +
                                                                   out.string());
    EXPECT_EQ(r.status, 1) << c.what << "\n" << r.err;
    const auto lines = lines_with(r.err, "skinlab-predict: error:", false);
    ASSERT_EQ(lines.size(), 1u) << c.what << "\n" << r.err;
    for (const auto& part : c.expected) {
      EXPECT_NE(lines[0].find(part), std::string::npos) << c.what << ": '" << part << "' not in\n"
                                                        << lines[0];
    }
    EXPECT_FALSE(fs::exists(out)) << c.what;
  }
  EXPECT_EQ(files_in(model), (std::vector<std::string>{"config.yaml", "parameters.h5",
                                                       "preparation.yaml"}))
      << "no temporary file left beside the parameter file";
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

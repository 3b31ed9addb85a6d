#include "framework/geometry/import_character.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "framework/geometry/lbs.hpp"
#include "tests/geometry/gltf_writer.hpp"
#include "tests/test_util.hpp"

namespace skinlab::geometry {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::GltfMesh;
using skinlab::testing::GltfScene;
using skinlab::testing::GltfSkin;
using skinlab::testing::TempDir;

// Installed by scripts/setup (Debian package minetest-data; model CC BY-SA 3.0).
const std::filesystem::path kMinetestPlayer =
    "/usr/share/games/minetest/games/minetest_game/mods/player_api/models/character.b3d";

Eigen::Matrix4f translation(float x, float y, float z) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m.topRightCorner<3, 1>() = Eigen::Vector3f(x, y, z);
  return m;
}

Eigen::Vector3d row(const Eigen::MatrixXd& M, Eigen::Index i) { return M.row(i).transpose(); }

/// Joints in the subtree of j (j included).
std::vector<bool> subtree(const Skeleton& s, int j) {
  std::vector<bool> in(s.num_joints(), false);
  for (int k = 0; k < s.num_joints(); ++k) {
    for (int a = k; a >= 0; a = s.parents[a]) {
      if (a == j) in[k] = true;
    }
  }
  return in;
}

/// 4 vertices, 2 triangles along +y; v0, v1 on joint 0, v2 on joint 1, v3 half and half.
GltfMesh strip(const std::string& name, float x0) {
  GltfMesh m;
  m.name = name;
  m.positions = {{x0, 0, 0}, {x0 + 1, 0, 0}, {x0, 2, 0}, {x0 + 1, 2, 0}};
  m.indices = {0, 1, 2, 1, 3, 2};
  m.joints = {{0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}};
  m.weights = {{1, 0, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}, {0.5f, 0.5f, 0, 0}};
  return m;
}

TEST(ImportCharacter, MinetestPlayerB3d) {
  // Fails (does not skip) when the asset is missing: scripts/setup installs it.
  ASSERT_TRUE(std::filesystem::exists(kMinetestPlayer))
      << kMinetestPlayer << " is missing; run scripts/setup (Debian package minetest-data)";
  ImportReport report;
  Character c = import_character(kMinetestPlayer, {}, &report);
  std::cout << "character.b3d: #V=" << c.mesh.num_vertices() << " #F=" << c.mesh.num_faces()
            << " #J=" << c.skeleton.num_joints() << " bind-pose mismatch "
            << report.max_bind_pose_mismatch << " at '" << report.max_bind_pose_mismatch_joint
            << "'\n";
  EXPECT_NO_THROW(c.validate());
  EXPECT_EQ(c.name, "character");
  // 7 textured boxes (body, head, hat layer, 2 arms, 2 legs), each 6 quads with their own UVs:
  // 7·24 vertices once JoinIdenticalVertices has merged B3D's per-corner vertices, 7·12 triangles.
  EXPECT_EQ(c.mesh.num_vertices(), 168);
  EXPECT_EQ(c.mesh.num_faces(), 84);
  ASSERT_EQ(c.skeleton.num_joints(), 6);
  EXPECT_EQ(report.num_bones, 6);
  EXPECT_EQ(report.num_mesh_instances, 1);
  EXPECT_EQ(report.num_rigid_vertices, 0);
  EXPECT_FALSE(report.source_up.has_value());
  // The mesh node "Player" above the LCA "Body" is dropped; every other bone hangs off Body.
  EXPECT_EQ(c.skeleton.names,
            (std::vector<std::string>{"Body", "Head", "Arm_Left", "Arm_Right", "Leg_Right",
                                      "Leg_Left"}));
  EXPECT_EQ(c.skeleton.parents, (std::vector<int>{-1, 0, 0, 0, 0, 0}));
  const Eigen::MatrixXd expected_joints = (Eigen::MatrixXd(6, 3) << 0, 6.3, 0, 0, 12.6, 0,
                                           -3.15, 11.55, 0, 3.15, 11.55, 0, 1.05, 6.3, 0,
                                           -1.05, 6.3, 0).finished();
  EXPECT_TRUE(c.skeleton.positions.isApprox(expected_joints, 1e-5)) << c.skeleton.positions;
  // Bone offsets and node transforms describe the same bind pose (up to float round-off).
  EXPECT_LT(report.max_bind_pose_mismatch, 1e-5);
  // Upright, Y up, feet at 0, 17 units tall (Minetest's 1.7 m player at 10 units per metre).
  EXPECT_NEAR(c.mesh.V.col(1).minCoeff(), 0.0, 1e-6);
  EXPECT_NEAR(c.mesh.V.col(1).maxCoeff(), 17.0, 1e-5);
  // Every vertex is weighted, by exactly one joint (Minetest rigs are rigid per box).
  for (Eigen::Index v = 0; v < c.weights.outerSize(); ++v) {
    int n = 0;
    for (SparseWeights::InnerIterator it(c.weights, v); it; ++it, ++n) EXPECT_EQ(it.value(), 1.0);
    EXPECT_EQ(n, 1) << "vertex " << v;
  }
  // The B3D importer's Z mirror comes with a winding flip, so the boxes stay outward-facing:
  // the enclosed signed volume is positive.
  double volume = 0;
  for (int f = 0; f < c.mesh.num_faces(); ++f) {
    volume += row(c.mesh.V, c.mesh.F(f, 0))
                  .dot(row(c.mesh.V, c.mesh.F(f, 1)).cross(row(c.mesh.V, c.mesh.F(f, 2)))) / 6;
  }
  EXPECT_GT(volume, 0);

  // LBS with the identity pose reproduces the bind pose exactly.
  const std::vector<Eigen::Matrix3d> rest(6, Eigen::Matrix3d::Identity());
  const Eigen::MatrixXd same = lbs(c.mesh.V, c.weights, forward_kinematics(c.skeleton, rest));
  const double identity_error = (same - c.mesh.V).cwiseAbs().maxCoeff();
  std::cout << "character.b3d: max |LBS(identity) - V| = " << identity_error << "\n";
  EXPECT_EQ(identity_error, 0.0);

  // Posing one joint moves exactly the vertices weighted to it or its descendants.
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (int j = 0; j < 6; ++j) {
    std::vector<Eigen::Matrix3d> pose = rest;
    pose[j] = turn;
    const Eigen::MatrixXd P = lbs(c.mesh.V, c.weights, forward_kinematics(c.skeleton, pose));
    const auto moving = subtree(c.skeleton, j);
    int moved = 0;
    for (Eigen::Index v = 0; v < c.weights.outerSize(); ++v) {
      bool on = false;
      for (SparseWeights::InnerIterator it(c.weights, v); it; ++it) on |= moving[it.col()];
      const double d = (P.row(v) - c.mesh.V.row(v)).norm();
      if (on) {
        EXPECT_GT(d, 1e-6) << c.skeleton.names[j] << ", vertex " << v;
        ++moved;
      } else {
        EXPECT_EQ(d, 0.0) << c.skeleton.names[j] << ", vertex " << v;
      }
    }
    EXPECT_GT(moved, 0) << c.skeleton.names[j];
  }
}

TEST(ImportCharacter, MinetestPlayerWithoutJoiningKeepsPerCornerVertices) {
  ASSERT_TRUE(std::filesystem::exists(kMinetestPlayer)) << kMinetestPlayer << " is missing";
  ImportOptions options;
  options.join_identical_vertices = false;
  const Character c = import_character(kMinetestPlayer, options);
  EXPECT_EQ(c.mesh.num_vertices(), 3 * 84);  // B3D import emits one vertex per face corner
  EXPECT_EQ(c.mesh.num_faces(), 84);
}

TEST(ImportCharacter, GltfSkeletonUnderRotatedScaledParent) {
  // Armature (rotated 90° about Z, scaled 2) holds the joint chain root → child and the mesh.
  GltfScene s;
  s.nodes = {R"({"name":"Armature","children":[1,3],"rotation":[0,0,0.70710678,0.70710678],"scale":[2,2,2]})",
             R"({"name":"root","children":[2]})", R"({"name":"child","translation":[0,1,0]})",
             R"({"name":"body","mesh":0,"skin":0})"};
  s.roots = {0};
  s.meshes = {strip("body", 0)};
  s.skins = {GltfSkin{{1, 2}, {translation(0, 0, 0), translation(0, -1, 0)}}};
  TempDir dir;
  ImportReport report;
  const Character c = import_character(dir.write("rig.gltf", s.json()), {}, &report);
  // The LCA of the bones is "root"; Armature above it and the mesh node are dropped.
  ASSERT_EQ(c.skeleton.names, (std::vector<std::string>{"root", "child"}));
  EXPECT_EQ(c.skeleton.parents, (std::vector<int>{-1, 0}));
  // Armature maps (x, y, z) to 2·(−y, x, z).
  EXPECT_TRUE(row(c.skeleton.positions, 0).isZero(1e-6));
  EXPECT_TRUE(row(c.skeleton.positions, 1).isApprox(Eigen::Vector3d(-2, 0, 0), 1e-6));
  EXPECT_TRUE(row(c.mesh.V, 3).isApprox(Eigen::Vector3d(-4, 2, 0), 1e-6));
  EXPECT_LT(report.max_bind_pose_mismatch, 1e-6);
  EXPECT_EQ(c.weights.coeff(0, 0), 1.0);
  EXPECT_EQ(c.weights.coeff(2, 1), 1.0);
  EXPECT_NEAR(c.weights.coeff(3, 0), 0.5, 1e-7);
  EXPECT_NEAR(c.weights.coeff(3, 1), 0.5, 1e-7);
}

TEST(ImportCharacter, GltfMeshNodeTransformAndInverseBindMatrices) {
  // The mesh node is moved by +5 in x; the inverse bind matrices map its mesh space to the
  // joints' spaces (assimp's mOffsetMatrix convention), so joints sit at G(mesh)·inverse(IBM).
  GltfScene s;
  s.nodes = {R"({"name":"hip","children":[1],"translation":[5,0,0]})",
             R"({"name":"knee","translation":[0,1,0]})",
             R"({"name":"legs","mesh":0,"skin":0,"translation":[5,0,0]})"};
  s.roots = {0, 2};
  s.meshes = {strip("legs", 0)};
  s.skins = {GltfSkin{{0, 1}, {translation(0, 0, 0), translation(0, -1, 0)}}};
  TempDir dir;
  ImportReport report;
  const Character c = import_character(dir.write("legs.gltf", s.json()), {}, &report);
  ASSERT_EQ(c.skeleton.names, (std::vector<std::string>{"hip", "knee"}));
  EXPECT_TRUE(row(c.skeleton.positions, 0).isApprox(Eigen::Vector3d(5, 0, 0), 1e-6));
  EXPECT_TRUE(row(c.skeleton.positions, 1).isApprox(Eigen::Vector3d(5, 1, 0), 1e-6));
  EXPECT_TRUE(row(c.mesh.V, 1).isApprox(Eigen::Vector3d(6, 0, 0), 1e-6));
  EXPECT_TRUE(row(c.mesh.V, 3).isApprox(Eigen::Vector3d(6, 2, 0), 1e-6));
  EXPECT_LT(report.max_bind_pose_mismatch, 1e-6);
}

TEST(ImportCharacter, BindPoseComesFromOffsetsWhenNodesArePosed) {
  // The node "knee" is stored bent away (at y = 3) while the skin was bound with it at y = 1:
  // the joint goes where the inverse bind matrix says, and the disagreement is reported.
  GltfScene s;
  s.nodes = {R"({"name":"hip","children":[1]})", R"({"name":"knee","translation":[0,3,0]})",
             R"({"name":"legs","mesh":0,"skin":0})"};
  s.roots = {0, 2};
  s.meshes = {strip("legs", 0)};
  s.skins = {GltfSkin{{0, 1}, {translation(0, 0, 0), translation(0, -1, 0)}}};
  TempDir dir;
  ImportReport report;
  const Character c = import_character(dir.write("posed.gltf", s.json()), {}, &report);
  EXPECT_TRUE(row(c.skeleton.positions, 1).isApprox(Eigen::Vector3d(0, 1, 0), 1e-6));
  EXPECT_NEAR(report.max_bind_pose_mismatch, 2.0, 1e-6);
  EXPECT_EQ(report.max_bind_pose_mismatch_joint, "knee");
}

TEST(ImportCharacter, GltfTwoSkinnedMeshesMergeByJointName) {
  // Mesh "b" uses a second skin listing the same joints in the opposite order.
  GltfScene s;
  s.nodes = {R"({"name":"root","children":[1]})", R"({"name":"child","translation":[0,1,0]})",
             R"({"name":"a","mesh":0,"skin":0})", R"({"name":"b","mesh":1,"skin":1})"};
  s.roots = {0, 2, 3};
  GltfMesh b = strip("b", 3);
  for (auto& j : b.joints) {
    for (auto& k : j) k = static_cast<std::uint8_t>(1 - k);
  }
  // v3's joints become {1, 0, ..}: skin-1 joint 1 is node "root", joint 0 is node "child".
  b.weights[3] = {0.25f, 0.75f, 0, 0};
  s.meshes = {strip("a", 0), b};
  s.skins = {GltfSkin{{0, 1}, {translation(0, 0, 0), translation(0, -1, 0)}},
             GltfSkin{{1, 0}, {translation(0, -1, 0), translation(0, 0, 0)}}};
  TempDir dir;
  ImportReport report;
  const Character c = import_character(dir.write("two.gltf", s.json()), {}, &report);
  EXPECT_EQ(report.num_mesh_instances, 2);
  ASSERT_EQ(c.mesh.num_vertices(), 8);
  ASSERT_EQ(c.mesh.num_faces(), 4);
  ASSERT_EQ(c.skeleton.num_joints(), 2);
  EXPECT_EQ(c.mesh.F.row(2), Eigen::RowVector3i(4, 5, 6));
  EXPECT_EQ(c.mesh.F.row(3), Eigen::RowVector3i(5, 7, 6));
  EXPECT_TRUE(row(c.mesh.V, 7).isApprox(Eigen::Vector3d(4, 2, 0), 1e-6));
  const int root = c.skeleton.find("root"), child = c.skeleton.find("child");
  EXPECT_EQ(c.weights.coeff(4, root), 1.0);
  EXPECT_EQ(c.weights.coeff(6, child), 1.0);
  EXPECT_NEAR(c.weights.coeff(7, root), 0.25, 1e-7);
  EXPECT_NEAR(c.weights.coeff(7, child), 0.75, 1e-7);
}

TEST(ImportCharacter, RigidAttachmentFollowsItsJoint) {
  // "hat" is an unskinned mesh below the joint node "child" (offset by +1 in y from it).
  GltfScene s;
  s.nodes = {R"({"name":"root","children":[1]})",
             R"({"name":"child","translation":[0,1,0],"children":[3]})",
             R"({"name":"body","mesh":0,"skin":0})",
             R"({"name":"hat","mesh":1,"translation":[0,1,0]})"};
  s.roots = {0, 2};
  GltfMesh hat;
  hat.name = "hat";
  hat.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}};
  hat.indices = {0, 1, 2};
  s.meshes = {strip("body", 0), hat};
  s.skins = {GltfSkin{{0, 1}, {translation(0, 0, 0), translation(0, -1, 0)}}};
  TempDir dir;
  ImportReport report;
  const Character c = import_character(dir.write("hat.gltf", s.json()), {}, &report);
  ASSERT_EQ(c.mesh.num_vertices(), 7);
  EXPECT_EQ(report.num_rigid_vertices, 3);
  // "hat" is a leaf helper node: not a joint.
  EXPECT_EQ(c.skeleton.names, (std::vector<std::string>{"root", "child"}));
  // Instances come in node depth-first order: root → child → hat, then body; so the hat's
  // vertices are 0..2, placed by G(hat) = translate(0, 2, 0).
  const int child = c.skeleton.find("child");
  for (int v = 0; v < 3; ++v) EXPECT_EQ(c.weights.coeff(v, child), 1.0) << v;
  EXPECT_TRUE(row(c.mesh.V, 1).isApprox(Eigen::Vector3d(1, 2, 0), 1e-6));
  EXPECT_EQ(c.weights.coeff(3, c.skeleton.find("root")), 1.0);
}

TEST(ImportCharacter, UnweightedVertexOutsideTheSkeletonIsAnError) {
  GltfScene s;
  s.nodes = {R"({"name":"root","children":[1]})", R"({"name":"child","translation":[0,1,0]})",
             R"({"name":"body","mesh":0,"skin":0})"};
  s.roots = {0, 2};
  GltfMesh m = strip("body", 0);
  m.weights[2] = {0, 0, 0, 0};
  s.meshes = {m};
  s.skins = {GltfSkin{{0, 1}, {translation(0, 0, 0), translation(0, -1, 0)}}};
  TempDir dir;
  const auto file = dir.write("loose.gltf", s.json());
  skinlab::testing::expect_error<GeometryError>([&] { import_character(file); },
                                                {"loose.gltf", "'body'", "vertex 2",
                                                 "no bone weight"});
}

// A documented assimp 5.2 behaviour, not ours: a glTF JOINTS_0 index beyond the skin's joint
// list is silently dropped by the glTF2 importer (as are weights ≤ 0), so the vertex keeps its
// other weights, which renormalisation then scales to 1.
TEST(ImportCharacter, GltfJointIndexBeyondTheSkinIsDroppedByAssimp) {
  GltfScene s;
  s.nodes = {R"({"name":"root","children":[1]})", R"({"name":"child","translation":[0,1,0]})",
             R"({"name":"body","mesh":0,"skin":0})"};
  s.roots = {0, 2};
  GltfMesh m = strip("body", 0);
  m.joints[3] = {0, 7, 0, 0};
  s.meshes = {m};
  s.skins = {GltfSkin{{0, 1}, {translation(0, 0, 0), translation(0, -1, 0)}}};
  TempDir dir;
  const Character c = import_character(dir.write("range.gltf", s.json()));
  EXPECT_EQ(c.weights.coeff(3, 0), 1.0);
  EXPECT_EQ(c.weights.coeff(3, 1), 0.0);
}

/// A COLLADA file: node "rig" (translated by +3 in z) holds the joint chain root → child and the
/// skinned 2-triangle strip; `weights` is the 3-entry weight array (vertices 0..2 use entry 0 on
/// root, root, child; vertex 3 uses entry 1 on root and entry 2 on child).
std::string collada(const std::string& weights) {
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries><geometry id="strip" name="strip"><mesh>
    <source id="strip-pos"><float_array id="strip-pos-array" count="12">0 0 0 1 0 0 0 2 0 1 2 0</float_array>
      <technique_common><accessor source="#strip-pos-array" count="4" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="strip-vtx"><input semantic="POSITION" source="#strip-pos"/></vertices>
    <triangles count="2"><input semantic="VERTEX" source="#strip-vtx" offset="0"/><p>0 1 2 1 3 2</p></triangles>
  </mesh></geometry></library_geometries>
  <library_controllers><controller id="skin"><skin source="#strip">
    <bind_shape_matrix>1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</bind_shape_matrix>
    <source id="skin-joints"><Name_array id="skin-joints-array" count="2">root child</Name_array>
      <technique_common><accessor source="#skin-joints-array" count="2" stride="1">
        <param name="JOINT" type="name"/></accessor></technique_common></source>
    <source id="skin-bind"><float_array id="skin-bind-array" count="32">
      1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1  1 0 0 0 0 1 0 -1 0 0 1 0 0 0 0 1</float_array>
      <technique_common><accessor source="#skin-bind-array" count="2" stride="16">
        <param name="TRANSFORM" type="float4x4"/></accessor></technique_common></source>
    <source id="skin-weights"><float_array id="skin-weights-array" count="3">)" +
         weights + R"(</float_array>
      <technique_common><accessor source="#skin-weights-array" count="3" stride="1">
        <param name="WEIGHT" type="float"/></accessor></technique_common></source>
    <joints><input semantic="JOINT" source="#skin-joints"/>
      <input semantic="INV_BIND_MATRIX" source="#skin-bind"/></joints>
    <vertex_weights count="4"><input semantic="JOINT" source="#skin-joints" offset="0"/>
      <input semantic="WEIGHT" source="#skin-weights" offset="1"/>
      <vcount>1 1 1 2</vcount><v>0 0 0 0 1 0 0 1 1 2</v></vertex_weights>
  </skin></controller></library_controllers>
  <library_visual_scenes><visual_scene id="scene">
    <node id="rig" name="rig"><translate>0 0 3</translate>
      <node id="root" name="root" sid="root" type="JOINT">
        <node id="child" name="child" sid="child" type="JOINT"><translate>0 1 0</translate></node>
      </node>
      <node id="body" name="body"><instance_controller url="#skin"><skeleton>#root</skeleton></instance_controller></node>
    </node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
}

TEST(ImportCharacter, ColladaSkin) {
  TempDir dir;
  ImportReport report;
  const Character c = import_character(dir.write("strip.dae", collada("1 0.25 0.75")), {}, &report);
  ASSERT_EQ(c.skeleton.names, (std::vector<std::string>{"root", "child"}));
  EXPECT_TRUE(row(c.skeleton.positions, 1).isApprox(Eigen::Vector3d(0, 1, 3), 1e-6));
  EXPECT_TRUE(row(c.mesh.V, 3).isApprox(Eigen::Vector3d(1, 2, 3), 1e-6));
  EXPECT_LT(report.max_bind_pose_mismatch, 1e-6);
  EXPECT_NEAR(c.weights.coeff(3, 0), 0.25, 1e-7);
  EXPECT_NEAR(c.weights.coeff(3, 1), 0.75, 1e-7);
}

// Also assimp's, not ours: its COLLADA importer drops weights ≤ 0 before we see them (so our
// negative-weight check only guards importers that do not), and renormalisation turns the
// remaining 1.5 into 1.
TEST(ImportCharacter, ColladaNegativeWeightIsDroppedByAssimpAndTheRestRenormalised) {
  TempDir dir;
  const Character c = import_character(dir.write("negative.dae", collada("1 1.5 -0.5")));
  EXPECT_EQ(c.weights.coeff(3, 0), 1.0);
  EXPECT_EQ(c.weights.coeff(3, 1), 0.0);
}

TEST(ImportCharacter, NoBonesIsAnError) {
  GltfScene s;
  s.nodes = {R"({"name":"statue","mesh":0})"};
  s.roots = {0};
  GltfMesh m = strip("statue", 0);
  m.joints.clear();
  m.weights.clear();
  s.meshes = {m};
  TempDir dir;
  const auto file = dir.write("statue.gltf", s.json());
  skinlab::testing::expect_error<GeometryError>([&] { import_character(file); },
                                                {"statue.gltf", "no bones"});
}

TEST(ImportCharacter, MissingOrUnreadableFileIsAnIoError) {
  TempDir dir;
  skinlab::testing::expect_error<IoError>(
      [&] { import_character(dir / "nowhere.fbx"); }, {"nowhere.fbx", "no such file"});
  const auto junk = dir.write("junk.gltf", "{ this is not json");
  skinlab::testing::expect_error<IoError>([&] { import_character(junk); },
                                          {"junk.gltf", "assimp cannot read it"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::geometry

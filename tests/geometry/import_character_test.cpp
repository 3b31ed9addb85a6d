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

using skinlab::testing::GltfAnimation;
using skinlab::testing::GltfChannel;
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

/// "hat" is an unskinned mesh below the joint node "child" (offset by +1 in y from it); the node
/// "child" is stored at y = `child_y`, the skin binds it at y = 1.
GltfScene hat_scene(double child_y) {
  GltfScene s;
  s.nodes = {R"({"name":"root","children":[1]})",
             R"({"name":"child","translation":[0,)" + std::to_string(child_y) + R"(,0],"children":[3]})",
             R"({"name":"body","mesh":0,"skin":0})",
             R"({"name":"hat","mesh":1,"translation":[0,1,0]})"};
  s.roots = {0, 2};
  GltfMesh hat;
  hat.name = "hat";
  hat.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}};
  hat.indices = {0, 1, 2};
  s.meshes = {strip("body", 0), hat};
  s.skins = {GltfSkin{{0, 1}, {translation(0, 0, 0), translation(0, -1, 0)}}};
  return s;
}

TEST(ImportCharacter, RigidAttachmentFollowsItsJoint) {
  const GltfScene s = hat_scene(1);
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
  EXPECT_EQ(report.max_rigid_misplacement, 0.0) << "the nodes are stored in the bind pose";
}

TEST(ImportCharacter, RigidAttachmentOfAPosedNodeIsMeasured) {
  // "child" stored at y = 3 while the skin binds it at y = 1: the hat stays where the node
  // hierarchy puts it (y = 4), 2 above where the bind pose would carry it.
  const GltfScene s = hat_scene(3);
  TempDir dir;
  ImportReport report;
  const Character c = import_character(dir.write("hat.gltf", s.json()), {}, &report);
  EXPECT_TRUE(row(c.mesh.V, 0).isApprox(Eigen::Vector3d(0, 4, 0), 1e-6));
  EXPECT_NEAR(report.max_rigid_misplacement, 2.0, 1e-6);
  EXPECT_EQ(report.max_rigid_misplacement_joint, "child");
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

/// A bar of 5 rows of 2 vertices (y = 0, 0.5, 1, 1.5, 2; x = 0, 0.2): rows 0–1 on joint 0, row 2
/// half and half, rows 3–4 on joint 1.
GltfMesh bar() {
  GltfMesh m;
  m.name = "bar";
  for (int r = 0; r < 5; ++r) {
    for (int c = 0; c < 2; ++c) {
      m.positions.emplace_back(0.2f * c, 0.5f * r, 0.0f);
      m.joints.push_back({0, 1, 0, 0});
      m.weights.push_back(r < 2 ? std::array<float, 4>{1, 0, 0, 0}
                          : r == 2 ? std::array<float, 4>{0.5f, 0.5f, 0, 0}
                                   : std::array<float, 4>{0, 1, 0, 0});
    }
  }
  for (int r = 0; r < 4; ++r) {
    const auto a = static_cast<std::uint16_t>(2 * r);
    m.indices.insert(m.indices.end(), {a, static_cast<std::uint16_t>(a + 1),
                                       static_cast<std::uint16_t>(a + 2),
                                       static_cast<std::uint16_t>(a + 1),
                                       static_cast<std::uint16_t>(a + 3),
                                       static_cast<std::uint16_t>(a + 2)});
  }
  return m;
}

/// The animated bar: "Armature" (node 0: 90° about Z, scale 2) holds the joints root (1) →
/// child (2, at y = 1) and the skinned mesh node "body" (3). Clips, in file order:
///   bend:      child turns 0 → 90° about Z and Armature moves 0 → 3 in z, over 1 s;
///   grow:      child scales 1 → 1.5 over 0.5 s (left out: not rigid);
///   body_only: only the mesh node moves (left out: animates no joint);
///   wave:      root turns 0 → 30° → 0 about X over 1 s, child has unit scale keys (kept).
GltfScene animated_bar() {
  GltfScene s;
  s.nodes = {R"({"name":"Armature","children":[1,3],"rotation":[0,0,0.70710678,0.70710678],"scale":[2,2,2]})",
             R"({"name":"root","children":[2]})", R"({"name":"child","translation":[0,1,0]})",
             R"({"name":"body","mesh":0,"skin":0})"};
  s.roots = {0};
  s.meshes = {bar()};
  s.skins = {GltfSkin{{1, 2}, {translation(0, 0, 0), translation(0, -1, 0)}}};
  const float h = static_cast<float>(std::sqrt(0.5));
  const float x30 = static_cast<float>(std::sin(M_PI / 12)), w30 = static_cast<float>(std::cos(M_PI / 12));
  s.animations = {
      GltfAnimation{"bend",
                    {GltfChannel{2, "rotation", {0, 1}, {0, 0, 0, 1, 0, 0, h, h}},
                     GltfChannel{0, "translation", {0, 1}, {0, 0, 0, 0, 0, 3}}}},
      GltfAnimation{"grow", {GltfChannel{2, "scale", {0, 0.5f}, {1, 1, 1, 1.5f, 1.5f, 1.5f}}}},
      GltfAnimation{"body_only", {GltfChannel{3, "translation", {0, 1}, {0, 0, 0, 5, 0, 0}}}},
      GltfAnimation{"wave",
                    {GltfChannel{1, "rotation", {0, 0.5f, 1}, {0, 0, 0, 1, x30, 0, 0, w30, 0, 0, 0, 1}},
                     GltfChannel{2, "scale", {0, 1}, {1, 1, 1, 1, 1, 1}}}}};
  return s;
}

Eigen::Affine3d affine(const Eigen::Matrix3d& linear, const Eigen::Vector3d& t) {
  Eigen::Affine3d a = Eigen::Affine3d::Identity();
  a.linear() = linear;
  a.translation() = t;
  return a;
}

/// LBS of the character with frame · bind⁻¹ per joint.
Eigen::MatrixXd pose(const Character& c, const std::vector<Eigen::Isometry3d>& frame,
                     const std::vector<Eigen::Isometry3d>& bind) {
  std::vector<Eigen::Affine3d> T(bind.size());
  for (std::size_t j = 0; j < T.size(); ++j) T[j] = Eigen::Affine3d((frame[j] * bind[j].inverse()).matrix());
  return lbs(c.mesh.V, c.weights, T);
}

/// The animated bar imported with its motion, its clips sampled at `clip_fps` (0: none).
Character import_animated_bar(double clip_fps, ImportedMotion& motion) {
  TempDir dir;
  ImportOptions options;
  options.clip_fps = clip_fps;
  return import_character(dir.write("bar.gltf", animated_bar().json()), options, nullptr, &motion);
}

TEST(ImportCharacter, BindTransformsPlaceTheJoints) {
  ImportedMotion motion;
  const Character c = import_animated_bar(0, motion);
  ASSERT_EQ(c.skeleton.names, (std::vector<std::string>{"root", "child"}));
  EXPECT_EQ(motion.no_bind, "");
  ASSERT_EQ(motion.bind.size(), 2u);
  for (int j = 0; j < 2; ++j) {
    EXPECT_LT((motion.bind[j].translation() - row(c.skeleton.positions, j)).norm(), 1e-9) << j;
    // The Armature's scale 2 is divided out: what is left is its 90° turn about Z.
    EXPECT_TRUE(motion.bind[j].linear().isApprox(
        Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-6));
  }
  EXPECT_TRUE(row(c.skeleton.positions, 1).isApprox(Eigen::Vector3d(-2, 0, 0), 1e-6));
  // Without clip_fps no clip is sampled, but the file's are counted.
  EXPECT_TRUE(motion.clips.empty());
  EXPECT_EQ(motion.num_file_clips, 4);
  EXPECT_TRUE(motion.left_out.empty());
}

TEST(ImportCharacter, ClipsPoseTheMeshWhereTheKeysPutIt) {
  ImportedMotion motion;
  const Character c = import_animated_bar(24, motion);
  EXPECT_EQ(motion.num_file_clips, 4);
  ASSERT_EQ(motion.clips.size(), 2u);
  EXPECT_EQ(motion.clips[0].name, "bend");
  EXPECT_EQ(motion.clips[1].name, "wave");
  EXPECT_EQ(motion.clips[0].fps, 24.0);
  ASSERT_EQ(motion.clips[0].frames.size(), 25u) << "1 s at 24 fps, both ends included";

  // bend at t = 0, 0.5 and 1 s (frames 0, 12, 24): the Armature A(t) = translate(0, 0, 3t) ·
  // 2·Rz(90°) carries everything; the child's part also turns by θ(t) = 90°·t about its joint
  // (mesh-space (0, 1, 0), where the inverse bind matrix puts it). Row 2 blends both halves.
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const GltfMesh mesh = bar();
  for (int f : {0, 12, 24}) {
    const double t = f / 24.0;
    const Eigen::Affine3d A = affine(2 * turn, Eigen::Vector3d(0, 0, 3 * t));
    const Eigen::Affine3d bend =
        affine(Eigen::AngleAxisd(M_PI / 2 * t, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
               Eigen::Vector3d(0, 1, 0)) *
        affine(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, -1, 0));
    const Eigen::MatrixXd posed = pose(c, motion.clips[0].frames[f], motion.bind);
    for (int v = 0; v < 10; ++v) {
      const Eigen::Vector3d m = mesh.positions[v].cast<double>();
      const double w_child = mesh.weights[v][1];
      const Eigen::Vector3d expected = (1 - w_child) * (A * m) + w_child * (A * (bend * m));
      EXPECT_LT((row(posed, v) - expected).norm(), 1e-5) << "frame " << f << ", vertex " << v
                                                         << ": " << row(posed, v).transpose();
    }
  }
  // At 90° the tip (mesh (0, 2)) is at mesh (−1, 1), i.e. 2·Rz(90°)·(−1, 1, 0) + (0, 0, 3).
  EXPECT_TRUE(row(pose(c, motion.clips[0].frames[24], motion.bind), 8)
                  .isApprox(Eigen::Vector3d(-2, -2, 3), 1e-5));

  // The frames of the first sample of a clip that starts from the stored pose are the bind.
  for (int j = 0; j < 2; ++j) {
    EXPECT_TRUE(motion.clips[1].frames[0][j].isApprox(motion.bind[j], 1e-6)) << j;
  }
}

TEST(ImportCharacter, RigidlyWeightedVerticesStayRigidInEveryFrame) {
  ImportedMotion motion;
  const Character c = import_animated_bar(30, motion);
  ASSERT_EQ(motion.clips.size(), 2u);
  const GltfMesh mesh = bar();
  double worst = 0, most_moved = 0;
  for (const ImportedClip& clip : motion.clips) {
    for (const auto& frame : clip.frames) {
      ASSERT_EQ(frame.size(), 2u);
      const Eigen::MatrixXd posed = pose(c, frame, motion.bind);
      most_moved = std::max(most_moved, (posed - c.mesh.V).rowwise().norm().maxCoeff());
      for (int u = 0; u < 10; ++u) {
        for (int v = u + 1; v < 10; ++v) {
          if (mesh.weights[u][0] == 0.5f || mesh.weights[u] != mesh.weights[v]) continue;
          const double before = (row(c.mesh.V, u) - row(c.mesh.V, v)).norm();
          worst = std::max(worst, std::abs((row(posed, u) - row(posed, v)).norm() - before));
        }
      }
    }
  }
  std::cout << "bar: largest change of a rigid pair's distance " << worst << ", largest move "
            << most_moved << "\n";
  EXPECT_LT(worst, 1e-5);
  EXPECT_GT(most_moved, 1.0);
}

TEST(ImportCharacter, ScalingAndJointlessClipsAreLeftOutAndCounted) {
  TempDir dir;
  const auto file = dir.write("bar.gltf", animated_bar().json());
  ImportOptions options;
  options.clip_fps = 24;
  ImportedMotion motion;
  import_character(file, options, nullptr, &motion);
  EXPECT_EQ(motion.num_scaled_clips, 1);
  EXPECT_EQ(motion.num_unread_clips, 0);
  ASSERT_EQ(motion.left_out.size(), 2u);
  EXPECT_NE(motion.left_out[0].find("'grow': joint 'child' is scaled at frame 1"), std::string::npos)
      << motion.left_out[0];
  EXPECT_NE(motion.left_out[1].find("'body_only': no channel animates a joint"), std::string::npos)
      << motion.left_out[1];

  // max_clips counts kept clips only: grow and body_only are passed over, wave is not read.
  options.max_clips = 1;
  import_character(file, options, nullptr, &motion);
  ASSERT_EQ(motion.clips.size(), 1u);
  EXPECT_EQ(motion.clips[0].name, "bend");
  EXPECT_EQ(motion.num_unread_clips, 3);
  EXPECT_TRUE(motion.left_out.empty());

  options.max_clips = 0;
  import_character(file, options, nullptr, &motion);
  EXPECT_TRUE(motion.clips.empty());
  EXPECT_EQ(motion.num_unread_clips, 4);
  EXPECT_EQ(motion.bind.size(), 2u) << "the bind does not depend on clips";

  options.max_clips = 8;
  options.clip_fps = -1;
  skinlab::testing::expect_error<GeometryError>([&] { import_character(file, options); },
                                                {"bar.gltf", "clip_fps"});
}

TEST(ImportCharacter, NonUniformBindScaleLeavesNoBind) {
  // The Armature scales x only: joint transforms are no longer rotations times one scale, and
  // frame · bind⁻¹ could not be written rigidly; the character itself still imports.
  GltfScene s = animated_bar();
  s.nodes[0] = R"({"name":"Armature","children":[1,3],"scale":[1,2,1]})";
  TempDir dir;
  ImportOptions options;
  options.clip_fps = 24;
  ImportedMotion motion;
  const Character c = import_character(dir.write("stretched.gltf", s.json()), options, nullptr, &motion);
  EXPECT_EQ(c.skeleton.num_joints(), 2);
  EXPECT_TRUE(motion.bind.empty());
  EXPECT_TRUE(motion.clips.empty());
  EXPECT_NE(motion.no_bind.find("joint 'root'"), std::string::npos) << motion.no_bind;
  EXPECT_NE(motion.no_bind.find("uniform positive scale"), std::string::npos) << motion.no_bind;
}

TEST(ImportCharacter, MeshesBindingAJointDifferentlyLeaveNoBind) {
  // Two meshes share the skin, but the second's node is moved by 1 in x: B(bone) = G(mesh) ·
  // inverse(IBM) differs between them, and one bind per joint cannot pose both.
  GltfScene s;
  s.nodes = {R"({"name":"root","children":[1]})", R"({"name":"child","translation":[0,1,0]})",
             R"({"name":"a","mesh":0,"skin":0})", R"({"name":"b","mesh":1,"skin":0,"translation":[1,0,0]})"};
  s.roots = {0, 2, 3};
  s.meshes = {strip("a", 0), strip("b", 3)};
  s.skins = {GltfSkin{{0, 1}, {translation(0, 0, 0), translation(0, -1, 0)}}};
  TempDir dir;
  ImportedMotion motion;
  import_character(dir.write("two.gltf", s.json()), {}, nullptr, &motion);
  EXPECT_TRUE(motion.bind.empty());
  EXPECT_NE(motion.no_bind.find("meshes bind joint"), std::string::npos) << motion.no_bind;
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

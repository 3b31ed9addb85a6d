#pragma once
/// \file
/// Import of a rigged, skinned character (mesh, skeleton, per-joint weights) through the Open
/// Asset Importer (assimp 5.2): FBX, COLLADA, glTF/GLB, B3D, SMD, X, MD5 and every other format
/// assimp reads with bones.
///
/// Frames. Everything is returned in the file's world frame (the frame of assimp's root node),
/// in the bind pose, in file units (no axis change, no scaling: see normalize.hpp):
///   - a vertex v of mesh m attached to node N becomes G(N)·v, where G(N) is N's global transform
///     (the product of aiNode::mTransformation from the root down to N);
///   - a joint whose node is a bone of a skinned mesh m attached to node N is placed at the
///     translation of its bind-pose global transform
///         B(bone) = G(N) · inverse(aiBone::mOffsetMatrix),
///     because assimp defines mOffsetMatrix as the map "from mesh space to bone space in bind
///     pose" (aiBone docs, mesh.h), i.e. mOffsetMatrix = B(bone)⁻¹ · G(N). For glTF, assimp
///     stores the skin's inverseBindMatrices as mOffsetMatrix, so the formula treats them as
///     relative to the mesh node's space;
///   - a joint whose node is no aiBone (an ancestor kept for connectivity) is placed at the
///     translation of its node global transform G(node).
/// B(bone) and G(bone node) agree when the file's node hierarchy is stored in the bind pose; the
/// largest disagreement is measured and returned in ImportReport (and logged as a warning above
/// ImportOptions::bind_pose_tolerance). On Minetest's character.b3d (mesh node "Player" at the
/// identity) the positions agree to 1.3e-8 file units (float round-off) for all 6 bones.
///
/// Skeleton. The joints are the nodes named by aiBones (of every mesh) plus their ancestors up
/// to the lowest common ancestor (LCA) of all bone nodes, which is the single root. Nodes above
/// the LCA and nodes that are neither bones nor on a path from a bone to the LCA (helper leaves,
/// mesh nodes, cameras) are dropped. Joints are in depth-first pre-order of the node tree, so a
/// parent always precedes its children. Joint names are node names; an empty name becomes
/// "joint<k>" and a repeated one gets a suffix "_<n>" so that names are unique.
///
/// Weights are per joint (#V×#J): aiBone weights go to the bone's own node, which is the start
/// joint of the bones leaving it (RigNet's convention). Several meshes (and several instances of
/// one mesh) are concatenated into one Mesh in node depth-first order, face indices offset, and
/// their weights are merged by joint. A vertex with no weight (a rigid attachment, e.g. a helmet
/// mesh that is a child of the head bone's node) gets weight 1 on the nearest joint among its
/// mesh node and that node's ancestors; if there is none it is a GeometryError naming the mesh
/// and the vertex. Finally the weights are checked and renormalised (check_weights) and the
/// character validated.
///
/// Post-processing (aiProcess flags):
///   - aiProcess_Triangulate: the Mesh is triangles only. Point and line primitives are dropped
///     (their vertices are kept, but are referenced by no face).
///   - aiProcess_JoinIdenticalVertices (ImportOptions::join_identical_vertices, on by default):
///     importers such as B3D emit one vertex per face corner (character.b3d: 252 = 3·84 vertices
///     without it, 168 with it), which leaves every triangle disconnected; this step merges vertices whose attributes are all identical
///     (position, normal, UVs, ...) keeping the first occurrence's order, and remaps bone weights.
///     Vertices that differ only in normal or UV (texture seams) stay split; merging coincident
///     positions is a later pre-processing step, not the importer's job.
///   Deliberately not used: ValidateDataStructure, because it rejects whole files for flaws in
///   parts we do not read: on Minetest's character.b3d it fails with "aiNodeAnim::mPositionKeys
///   [220].mTime (221) is larger than aiAnimation::mDuration (220)", an off-by-one between key
///   times and duration in assimp 5.2's B3D animation import. The face and bone
///   index checks it would make are done here instead, with the mesh and bone named.
///   PreTransformVertices (deletes bones and bakes nodes), LimitBoneWeights
///   (drops weights), SortByPType / SplitLargeMeshes / SplitByBoneCount (split meshes),
///   FindDegenerates / FindInvalidData (remove faces and change counts), OptimizeGraph /
///   OptimizeMeshes / ImproveCacheLocality (reorder nodes, meshes or vertices), MakeLeftHanded.
/// Importer properties: AI_CONFIG_IMPORT_REMOVE_EMPTY_BONES = false, so that bones without
/// weights (end joints) stay joints; AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS = false, so that FBX
/// pivots are folded into the bone node instead of creating "$AssimpFbx$" helper nodes between
/// bones.
///
/// Importer behaviour seen in the tests: assimp 5.2's glTF2 and COLLADA importers drop weights
/// ≤ 0, and glTF2 drops JOINTS_0 indices beyond the skin's joint list, before we see them; the
/// vertex keeps its other weights and renormalisation scales them to sum 1.
///
/// Format quirk (B3D): assimp's B3D importer converts the left-handed Blitz3D data to its
/// right-handed convention by mirroring Z (MakeLeftHanded) and flipping the winding, so node
/// rotations of Minetest's player model come out as 180° turns (diag(-1,1,-1) or diag(-1,-1,1))
/// and X of the result is the file's X. The bind pose is nevertheless consistent: the mirrored
/// offsets and node transforms agree (see above), and the mesh is upright with Y up, feet at y=0.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::geometry {

struct ImportOptions {
  /// aiProcess_JoinIdenticalVertices (see the file comment).
  bool join_identical_vertices = true;
  /// A bone whose bind-pose position B(bone) and node position G(node) differ by more than this
  /// fraction of the mesh's bounding-box diagonal is reported with a warning in the log.
  double bind_pose_tolerance = 1e-4;
  /// Passed to check_weights after merging (renormalise: rows are divided by their sum).
  WeightCheck weights{1e-3, true};
};

/// What the import found, for logs and tests.
struct ImportReport {
  int num_mesh_instances = 0;  ///< (node, mesh) pairs merged into the Mesh
  int num_bones = 0;           ///< distinct aiBone names
  int num_rigid_vertices = 0;  ///< unweighted vertices given weight 1 on their host joint
  /// Largest |B(bone) translation − G(bone node) translation| over bones and meshes, file units.
  double max_bind_pose_mismatch = 0;
  std::string max_bind_pose_mismatch_joint;  ///< where it occurs ("" if no bone)
  /// The up direction the file declares through assimp's metadata "UpAxis"/"UpAxisSign"
  /// (set by the FBX importer, which does not rotate the scene itself); empty when absent.
  /// Pass it to NormalizeOptions::source_up.
  std::optional<Eigen::Vector3d> source_up;
};

/// Reads `file` and returns its character (name = file stem) in the bind pose, in the file's
/// world frame and units, with weights #V×#J checked and renormalised.
///
/// Throws skinlab::IoError naming the file if it does not exist or assimp cannot read it (with
/// assimp's message), and GeometryError naming the file for: no mesh, no bones, a bone without a
/// node of the same name, a bone vertex index out of range or a negative / non-finite weight
/// (naming mesh, bone and vertex), an unweighted vertex outside the skeleton (naming mesh and
/// vertex), and anything Character::validate rejects.
Character import_character(const std::filesystem::path& file, const ImportOptions& options = {},
                           ImportReport* report = nullptr);

}  // namespace skinlab::geometry

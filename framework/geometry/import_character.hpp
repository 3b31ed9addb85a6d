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
/// Bind transforms and clips (ImportedMotion, only when asked for). The bind-pose global
/// transform of joint j, in the same frame, is
///     bind(j) = B(bone) = G(N) · inverse(mOffsetMatrix)   for a bone (the first mesh's, as above),
///     bind(j) = G(node)                                    for a joint that is no bone,
/// so that bind(j).translation() is the joint's position. A viewer (assimp's, or glTF's, which
/// ignores the skinned mesh node's transform) draws a vertex v of mesh m (node N) skinned to
/// bone node J at time t at Σ w · G_t(J) · mOffsetMatrix · v, where G_t is the global transform
/// with the clip's local transforms in place of mTransformation on the animated nodes. Since the
/// character holds V = G(N)·v and inverse(bind(j)) = mOffsetMatrix · inverse(G(N)), this is
///     G_t(J) · inverse(bind(j)) · V,
/// i.e. LBS of the returned mesh with frame(j, t) = G_t(J) and bind(j): joint j's frame at time t
/// is its node's animated global transform in the file's world frame. Assimp's mesh-space
/// skinning matrix inverse(G(N)) · G_t(J) · mOffsetMatrix is the same transform conjugated into
/// mesh space, and the mesh node's own animation cancels out of it. The bind pose this returns
/// is what a viewer draws at rest only where G_rest(J) = bind(j); a file whose inverse bind
/// matrices are relative to the world (glTF's rule) under a scaled mesh node has bind(j) =
/// G(N) · G_rest(J), and its clips then scale every joint relative to the bind by G(N)'s scale
/// and are left out (below): Godot's platformer player.glb, mesh node at scale 0.3.
///
/// Rigidly attached vertices (weight 1 on their host joint, above) are placed by their mesh
/// node's G(N), i.e. in the node hierarchy's stored pose, and a viewer moves them with G_t(N).
/// LBS with the host's bind(j) = B(bone) reproduces that only where B(bone) = G(host node) (the
/// hierarchy is stored in the bind pose) and no node between host and mesh node is animated;
/// otherwise the attachment is moved rigidly with its host but keeps the offset it has in the
/// returned bind pose, ImportReport::max_rigid_misplacement. (Quaternius' astronauts' pistol, a
/// mesh node under a finger bone, lies 2.6 units, 0.45 of the bounding-box diagonal, from the
/// bind-pose hand; moving it there would change characters read before clips were.)
///
/// Rigid transforms. Hierarchies often scale uniformly above the skeleton (an armature node at
/// scale 0.01 or 100); a joint's global transform then is s·R plus a translation. Since
/// (s·R_t, t_t) · (s·R_b, t_b)⁻¹ = (R_t, t_t) · (R_b, t_b)⁻¹, dividing the same s out of bind and
/// frames leaves LBS unchanged, so both are returned as rotations (the nearest rotation, U·Vᵀ of
/// the SVD) and translations. A joint whose bind transform is not a rotation with a uniform
/// positive scale (to ImportOptions::clip_scale_tolerance, relative; non-uniform scale, shear,
/// a mirror) makes the bind unrepresentable: bind and clips stay empty and ImportedMotion::
/// no_bind says why. The same holds when two meshes bind one bone differently (their B(bone)
/// differ by more than bind_pose_tolerance of the diagonal in translation or clip_scale_tolerance
/// in the linear part), since one bind per joint could not pose both meshes' vertices.
///
/// Sampling (ImportOptions::clip_fps > 0): clips in the file's order (aiScene::mAnimations),
/// each sampled at clip_fps from time 0 to its duration (aiAnimation::mDuration ticks at
/// mTicksPerSecond, 25 when 0), floor(duration·fps) + 1 frames. A node with a channel
/// (aiNodeAnim, matched by name, the first of several) gets the local transform T·R·S from its
/// position, rotation and scaling keys, each interpolated between the two keys around the time
/// (linearly for vectors, slerp for quaternions) and held constant before the first and after the
/// last key (glTF's and assimp's viewer behaviour; mPreState/mPostState are not read); a channel
/// without keys of one kind takes that part from the node's mTransformation; a node without a
/// channel keeps mTransformation. Assimp 5.2 does not keep glTF's STEP and CUBICSPLINE
/// interpolation (it stores the key values only), so such samplers are interpolated linearly.
/// A clip is left out, and counted, when at some frame a joint's scale differs from its bind
/// scale by more than clip_scale_tolerance (relative; any singular value of the global linear
/// part, or a mirror): its frames would not be rigid relative to the bind pose. It is also left
/// out when no channel animates a joint or a node above one (morph-target or prop clips), or
/// when its keys or duration are not finite or keys are out of time order.
///
/// Format quirk (B3D): assimp's B3D importer converts the left-handed Blitz3D data to its
/// right-handed convention by mirroring Z (MakeLeftHanded) and flipping the winding, so node
/// rotations of Minetest's player model come out as 180° turns (diag(-1,1,-1) or diag(-1,-1,1))
/// and X of the result is the file's X. The bind pose is nevertheless consistent: the mirrored
/// offsets and node transforms agree (see above), and the mesh is upright with Y up, feet at y=0.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

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
  /// With an ImportedMotion to fill: sample the file's clips at this many frames per second;
  /// 0 reads bind transforms only. Must be finite and ≥ 0.
  double clip_fps = 0;
  /// Stop after this many clips have been kept (left-out clips do not count). Must be ≥ 0.
  int max_clips = std::numeric_limits<int>::max();
  /// Relative tolerance on scales: of a joint's bind transform (uniform to this) and of its
  /// frames (equal to the bind scale to this), see the file comment.
  double clip_scale_tolerance = 1e-4;
};

/// What the import found, for logs and tests.
struct ImportReport {
  int num_mesh_instances = 0;  ///< (node, mesh) pairs merged into the Mesh
  int num_bones = 0;           ///< distinct aiBone names
  int num_rigid_vertices = 0;  ///< unweighted vertices given weight 1 on their host joint
  /// Largest |B(bone) translation − G(bone node) translation| over bones and meshes, file units.
  double max_bind_pose_mismatch = 0;
  std::string max_bind_pose_mismatch_joint;  ///< where it occurs ("" if no bone)
  /// Largest distance, in file units, between an unweighted (rigidly attached) vertex x and
  /// where its host joint's bind pose would carry it, |B(host) · G(host node)⁻¹ · x − x|: zero
  /// when the host node is stored in the bind pose. The vertex is not moved (see the file
  /// comment, "Bind transforms and clips"); logged as a warning above bind_pose_tolerance.
  double max_rigid_misplacement = 0;
  std::string max_rigid_misplacement_joint;  ///< its host joint ("" if no rigid vertex)
  /// The up direction the file declares through assimp's metadata "UpAxis"/"UpAxisSign"
  /// (set by the FBX importer, which does not rotate the scene itself); empty when absent.
  /// Pass it to NormalizeOptions::source_up.
  std::optional<Eigen::Vector3d> source_up;
};

/// One clip of the file, sampled (see the file comment).
struct ImportedClip {
  std::string name;  ///< aiAnimation::mName, "clip<k>" when empty (k: its index in the file)
  double fps = 0;    ///< ImportOptions::clip_fps
  /// frames[f][j]: joint j's global transform at time f / fps, rigid (the uniform scale of its
  /// bind transform divided out), in the returned character's frame and units.
  std::vector<std::vector<Eigen::Isometry3d>> frames;
};

/// The joints' bind-pose transforms and sampled clips, for LBS with frame · bind⁻¹ (the file
/// comment derives them).
struct ImportedMotion {
  /// bind[j]: joint j's bind-pose global transform, rigid; translation = skeleton position j.
  /// Empty when no_bind is set.
  std::vector<Eigen::Isometry3d> bind;
  std::string no_bind;  ///< why bind (and with it every clip) is empty; "" otherwise
  std::vector<ImportedClip> clips;  ///< the kept clips, in file order
  int num_file_clips = 0;    ///< aiScene::mNumAnimations
  int num_scaled_clips = 0;  ///< left out: a joint's scale changes (or mirrors)
  int num_unread_clips = 0;  ///< not looked at: max_clips were kept before them
  /// Every left-out clip as "'<name>': <reason>", scaled ones included, for the log.
  std::vector<std::string> left_out;
};

/// Reads `file` and returns its character (name = file stem) in the bind pose, in the file's
/// world frame and units, with weights #V×#J checked and renormalised. With `motion`, also the
/// joints' bind transforms and (ImportOptions::clip_fps > 0) the file's clips.
///
/// Throws skinlab::IoError naming the file if it does not exist or assimp cannot read it (with
/// assimp's message), and GeometryError naming the file for: no mesh, no bones, a bone without a
/// node of the same name, a bone vertex index out of range or a negative / non-finite weight
/// (naming mesh, bone and vertex), an unweighted vertex outside the skeleton (naming mesh and
/// vertex), and anything Character::validate rejects. A negative or non-finite clip_fps or a
/// negative max_clips is a GeometryError naming the file. Problems of the motion (no_bind,
/// left-out clips) are reported in `motion`, not thrown: the character itself is still good.
Character import_character(const std::filesystem::path& file, const ImportOptions& options = {},
                           ImportReport* report = nullptr, ImportedMotion* motion = nullptr);

}  // namespace skinlab::geometry

#pragma once
/// \file
/// Reader of OGRE's binary `.mesh` and `.skeleton` files (OGRE 1.x serialisers; format
/// reference: OgreMain/src/OgreMeshFileFormat.h, OgreMeshSerializerImpl.cpp and
/// OgreSkeletonSerializer.cpp of OGRE 14).
///
/// Both files are little-endian sequences of chunks `u16 id, u32 length` (length counts the
/// 6-byte header) after a header chunk 0x1000 whose version string ends at a newline; strings
/// inside chunks end at a newline too. OGRE itself reads chunks **sequentially** and uses a
/// chunk's length only to skip chunks it does not parse, and so does this reader: exporters of
/// the `[MeshSerializer_v1.41]` era write sub-mesh lengths that are 6 bytes short (Summoning
/// Wars' fire_slug.mesh), and the skeleton serialiser's bone lengths never count the bone name
/// (OGRE decides "has a scale" by comparing the length with 36 bytes; so does this reader).
/// A length must end inside the file where it is used (to skip a chunk); the mesh chunk
/// (M_MESH), which is read item by item, may claim more: OpenClonk's exporter wrote
/// `GraphicsAlchemist.mesh` and `GraphicsSteampunk.mesh` with an M_MESH length one byte past the
/// end of the file, which OpenClonk's own loader (StdMeshLoaderBinaryChunks.cpp) never looks at,
/// nor does OGRE's importMesh outside its debug-build chunk validation.
///
/// Mesh versions read: `[MeshSerializer_v1.100]`, `v1.10`, `v1.8`, `v1.41`, `v1.40`, `v1.30`.
/// Between these versions only chunks this reader skips differ (LOD levels, edge lists, poses,
/// vertex animation); geometry, sub-meshes, bone assignments and the skeleton link are the
/// same. Skeleton versions: `[Serializer_v1.10]` and `[Serializer_v1.80]`.
///
/// What is read:
/// - Geometry: the positions (semantic VES_POSITION, type FLOAT3 or FLOAT4) of the shared
///   vertex data (if any) and of every sub-mesh with its own vertex data, concatenated in that
///   order (shared block first, then sub-meshes in file order);
/// - triangles of every sub-mesh (operation type triangle list, strip or fan; point and line
///   sub-meshes give no triangle), with 16- or 32-bit indices into its vertex block;
/// - bone assignments (vertex, bone handle, weight) of the mesh (shared vertices) and of each
///   sub-mesh (its own vertices), as stored: not normalised, possibly more than 4 per vertex;
/// - the skeleton link (the `.skeleton` file name the mesh uses);
/// - bones (name, handle, parent, position, orientation, optional scale, all relative to the
///   parent) and skeletal animations (per-bone tracks of keyframes relative to the bind pose).
///
/// Every read is bounds-checked: a truncated or corrupt file throws IoError naming the file, the
/// chunk and its byte offset (datasets/byte_reader.hpp), never reads past the end.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace skinlab::datasets::ogre {

/// One stored bone assignment: `vertex` indexes OgreMesh::V (all blocks concatenated).
struct BoneAssignment {
  int vertex = 0;
  int bone = 0;  ///< bone handle in the skeleton
  double weight = 0;
};

struct OgreMesh {
  std::string version;        ///< e.g. "[MeshSerializer_v1.100]"
  std::string skeleton_link;  ///< the SKELETON_LINK chunk's file name; empty: a static mesh
  Eigen::MatrixXd V;          ///< #V×3 positions, model space, file units
  Eigen::MatrixXi F;          ///< #F×3 triangles (degenerate triangles of strips dropped)
  std::vector<BoneAssignment> assignments;
  int num_submeshes = 0;
  int num_dropped_degenerate = 0;  ///< triangles with a repeated index, not in F
};

struct OgreKeyframe {
  double time = 0;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  ///< applied after the bind's
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();          ///< added to the bind's
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();               ///< multiplies the bind's
};

struct OgreTrack {
  int bone = 0;  ///< bone handle
  std::vector<OgreKeyframe> keys;
};

struct OgreAnimation {
  std::string name;
  double length = 0;  ///< seconds
  std::vector<OgreTrack> tracks;
};

struct OgreBone {
  std::string name;
  int parent = -1;  ///< parent handle, -1 for a root
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< relative to the parent
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
};

struct OgreSkeleton {
  std::string version;          ///< e.g. "[Serializer_v1.80]"
  std::vector<OgreBone> bones;  ///< indexed by handle (handles are 0..n-1)
  std::vector<OgreAnimation> animations;
  /// SKELETON_ANIMATION_LINK targets (animations borrowed from other skeletons; not followed).
  std::vector<std::string> animation_links;
};

/// Parses a `.mesh` file's bytes; `source` names it in errors. Throws IoError (truncated,
/// unknown chunk, bad version) or GeometryError (indices out of range, unsupported position
/// type) naming `source`, the chunk and its byte offset.
OgreMesh parse_mesh(std::string_view data, const std::string& source);

/// Parses a `.skeleton` file's bytes. Throws IoError naming `source`, the chunk and offset for
/// truncation, unknown chunks, non-contiguous handles, a bad parent or a cycle.
OgreSkeleton parse_skeleton(std::string_view data, const std::string& source);

/// Ogre's derived (global) bind transform of every bone, indexed by handle: position, rotation
/// and scale composed as OGRE's Node does (a child's position is scaled by its parent's derived
/// scale, then rotated). Scales are returned separately since a Transform has none.
struct BindPose {
  std::vector<Eigen::Vector3d> position;
  std::vector<Eigen::Quaterniond> orientation;
  std::vector<Eigen::Vector3d> scale;
};
BindPose derive_bind_pose(const OgreSkeleton& skeleton);

/// The pose of `animation` at `time` seconds (keyframes interpolated as OGRE does by default:
/// linear translation and scale, normalised-linear rotation along the shortest path; bones
/// without a track stay in the bind pose), derived to global transforms.
BindPose sample_animation(const OgreSkeleton& skeleton, const OgreAnimation& animation,
                          double time);

}  // namespace skinlab::datasets::ogre

#pragma once
/// \file
/// The one preprocessed dataset file (layout: datasets/FORMAT.md). A `Dataset` holds characters
/// preprocessed as HeterSkinNet Sec. 4.1 (normalised, merged, subdivided; see preprocess.hpp),
/// the characters a builder or the preprocessing excluded with their reasons, and named splits
/// as index lists into the character list.
///
/// write_dataset writes through a temporary file renamed into place (H5Writer), so a crash never
/// leaves a partial file under the target name. read_dataset validates every shape and index
/// range and throws IoError naming the file and the dataset (HDF5 path) that is wrong.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "framework/data/source.hpp"
#include "framework/data/h5.hpp"
#include "framework/geometry/mesh.hpp"
#include "framework/geometry/skin_weights.hpp"

namespace skinlab::data {

/// Version of the layout written by this build, the only one it reads. Version 2 added the
/// optional per-character `leaf_tips`; version 3 stores every string fixed-length (versions 1
/// and 2 hold variable-length strings in HDF5's global heap, on whose damage libhdf5 can hang,
/// so they are refused with "re-run `skinlab prepare`").
inline constexpr std::int64_t kFormatVersion = 3;

/// Opens a dataset file and checks its root `format_version` (an int attribute, read before any
/// string): IoError for a foreign file (none), an older version ("written by an older skinlab
/// (format_version 2): re-run `skinlab prepare`") or a newer one. Every reader of a dataset file
/// goes through this.
std::unique_ptr<H5Reader> open_dataset_file(const std::filesystem::path& file);

/// What one distance type gives a character (HeterSkinNet Sec. 3.2: the top-K candidate bones of
/// every vertex and 1/D as a vertex attribute). K is min(top_k, #B).
struct DistanceData {
  RowMatrixXf D;              ///< #V×#B vertex–bone distance, metres (normalised 1 m frame)
  RowMatrixXi topk_index;     ///< #V×K bone indices, nearest first (ties: lower bone index)
  RowMatrixXf topk_distance;  ///< #V×K D at those bones, ascending along each row
  /// #V×K artist weight of each candidate bone (bone-level rule in preprocess.hpp): in [0, 1],
  /// rows sum to ≤ 1 (the weight on bones outside the top K is dropped, as in the paper).
  RowMatrixXf targets;
};

/// One animation clip: joint transforms in the normalised frame of the character.
struct AnimationData {
  std::string name;
  double fps = 0;  ///< frames per second, 0 when unknown
  /// #frames × #J × 12 float32: the first three rows of joint j's 4×4 global transform at a
  /// frame, row-major ([R | t], t in metres), in the normalised frame.
  std::vector<float> frames;
  int num_frames = 0;
  /// #J × 12 float32: bind-pose global transforms, same layout.
  std::vector<float> bind;
};

/// One joint's transform of an AnimationData array (12 float32, [R | t] row-major: a frame's or
/// the bind pose's entry of joint j starts at 12·j) as a rigid transform; the rotation is
/// re-orthonormalised (float32 storage leaves it orthogonal to ~1e-7 only, and dual quaternion
/// skinning and ACAP's polar decompositions expect a rotation).
Eigen::Isometry3d joint_transform(const float* m);

/// A character after preprocessing, everything in the normalised frame (Y up, 1 m tall).
struct PreparedCharacter {
  std::string name;  ///< unique in the dataset; an HDF5 name (no '/', not "." or "")
  RowMatrixXd V;     ///< #V×3 vertex positions, metres (after merging and subdivision)
  RowMatrixXi F;     ///< #F×3 triangle vertex indices into V
  std::vector<std::string> joint_names;  ///< #J
  std::vector<int> parents;              ///< #J parent index, −1 for the root
  RowMatrixXd joints;                    ///< #J×3 joint positions, metres
  RowMatrixXi bones;                     ///< #B×2 (start, end) joints; start = end: helper bone
  /// #J×3 or empty: the end of each leaf joint's helper bone (Skeleton::leaf_tips,
  /// distances/leaf_bones.hpp); empty: zero-length helper bones, the paper's construction.
  RowMatrixXd leaf_tips;
  geometry::SparseWeights weights;       ///< #V×#J artist weights, rows sum to 1
  /// #V_orig: the vertex of V that every vertex of the source mesh became (merge map; the first
  /// vertices of V are the merged originals, subdivision only appends).
  std::vector<int> vertex_map;
  /// 4×4 similarity [s·R, t; 0 0 0 1] from the source file's frame to the normalised frame. For
  /// an augmented copy, the original's similarity followed by the copy's own normalisation; the
  /// copy is a deformation of the source, not its image under this map.
  Eigen::Matrix4d normalisation = Eigen::Matrix4d::Identity();
  int subdivision_levels = 0;
  /// Per distance registry key (e.g. "hollow_dist").
  std::map<std::string, DistanceData> distances;
  /// Per binder registry key (e.g. "bone_heat"): #V×#B weights of that classical method on this
  /// mesh and these bones (preprocess.hpp step 4b), rows summing to 1. Empty unless the dataset
  /// was prepared with `preprocess.priors`.
  std::map<std::string, RowMatrixXf> priors;
  RowMatrixXi one_ring_edges;  ///< #E×2 directed edges (i, j), both directions of every edge
  RowMatrixXi geodesic_edges;  ///< #E_g×2 directed edges (i, j), geodesic radius 0.06, cap 10
  /// Uniform Laplacian L = D − A (laplacian.hpp) as #N triplets, row-major order.
  RowMatrixXi laplacian_indices;         ///< #N×2 (row, column)
  std::vector<double> laplacian_values;  ///< #N
  // Provenance (SourceCharacter).
  std::string source, path, licence, attribution, skeleton;
  /// Variant group (clean.hpp): splits never divide a group. Empty means the character alone
  /// (written as its own name).
  std::string group;
  /// For an augmented training copy (augment.hpp, named "<original>~aug<i>"): the name of the
  /// character it was made from; empty for every other character.
  std::string augmented_from;
  /// #J × 12 float32 (AnimationData's layout): the bind-pose global joint transforms in the
  /// normalised frame, whether or not the character has clips; empty when the source gives joint
  /// positions only, for an augmented copy, and in files written before it was stored (then a
  /// clip's AnimationData::bind, the same transforms, is the only copy). See bind_pose().
  std::vector<float> bind;
  std::vector<AnimationData> animations;

  bool is_augmented_copy() const { return !augmented_from.empty(); }
  /// The variant group as written to the file: `group`, or the character's own name when empty.
  const std::string& variant_group() const { return group.empty() ? name : group; }
  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_joints() const { return static_cast<int>(joint_names.size()); }
  int num_bones() const { return static_cast<int>(bones.rows()); }
  /// The bind pose (#J × 12, as `bind`): `bind`, else the first clip's, else nullptr.
  const std::vector<float>* bind_pose() const;
  /// The character's skeleton (names, parents, joint positions and leaf tips). Validates it and
  /// throws IoError naming the character when its `bones()` are not the stored `bones` (a file
  /// written with another bone convention).
  geometry::Skeleton rig() const;
  /// The character's mesh (`V`, `F`), in the normalised frame as stored: with rig(), what a
  /// binder is given.
  geometry::Mesh mesh() const;
};

/// Index lists into Dataset::characters.
struct Split {
  std::vector<int> train, val, test;
};

struct Dataset {
  std::vector<PreparedCharacter> characters;  ///< order of /character_names
  std::map<std::string, Split> splits;
  std::vector<datasets::Excluded> excluded;
  std::string git_commit = "unknown";  ///< commit the writing skinlab was built from ("-dirty-<diff hash>": modified)
  /// The resolved `preprocess:` and `distances:` config (YAML) the characters were made with;
  /// `skinlab prepare` reuses a partial character file only when this matches.
  std::string preparation;
};

/// Writes `dataset` to `file` atomically. Throws IoError for an invalid character name or a
/// duplicate name, a bind pose or clip whose arrays do not hold #J×12 values per pose (naming
/// the character), and on any HDF5 failure (naming the file and the dataset).
/// `deflate_level` as H5Writer (0: uncompressed, for intermediate files).
void write_dataset(const std::filesystem::path& file, const Dataset& dataset,
                   int deflate_level = kDeflateLevel);

/// Reads and validates a dataset file. Throws IoError naming the file and the HDF5 path for: a
/// missing file, a file that is not HDF5 or is truncated, a missing `format_version` (a foreign
/// file) or a version other than kFormatVersion (open_dataset_file), a variable-length string,
/// a missing dataset, a wrong shape, an index out
/// of range (faces ≥ #V, bones or CSR columns ≥ #J, parents, top-K ≥ #B, edges, Laplacian,
/// vertex map, split indices ≥ #characters), inconsistent CSR arrays, leaf tips or a bind pose
/// that are not #J×3 / #J×12, and non-finite values.
Dataset read_dataset(const std::filesystem::path& file);

/// Each character's unit of a dataset file, read from its attributes only (no arrays), for
/// statistics over units that are independent where characters are not (`skinlab table --per`):
/// `per` "family" gives `<source>/<skeleton>` (a skeleton family; 0 A.D.'s 34 human garments
/// share one), "group" gives `<source>/<group>` (a variant group, clean.hpp). The source is part
/// of the unit because family and group names are only unique within a source. Throws IoError
/// as open_dataset_file and for a character without its group or attribute (naming both), and
/// ConfigError for another `per`.
std::map<std::string, std::string> read_character_units(const std::filesystem::path& file,
                                                        const std::string& per);

}  // namespace skinlab::data

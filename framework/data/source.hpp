#pragma once
/// \file
/// Interface of the `dataset` registry: a builder reads one raw source (a game data package, a
/// folder of rigged files) into characters with their provenance. Cleaning, preprocessing
/// (HeterSkinNet Sec. 4.1), splitting and the HDF5 file are shared code in framework/data; a
/// builder only reads.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "framework/geometry/skin_weights.hpp"

namespace skinlab::datasets {

/// A clip of real poses of one character's skeleton.
struct Animation {
  std::string name;  ///< e.g. "biped/walk" (source-specific)
  double fps = 0;    ///< frames per second, 0 when unknown
  /// frames[f][j]: joint j's global transform at frame f, in the character's frame and units
  /// (the frame of Character::skeleton in the bind pose). LBS moves a vertex by
  /// frames[f][j] · bind(j)⁻¹, where bind(j) is the joint's bind-pose global transform.
  std::vector<std::vector<Eigen::Isometry3d>> frames;
  /// bind[j]: joint j's bind-pose global transform (same frame), so that the above is defined
  /// even where bind-pose joint orientations are not the identity.
  std::vector<Eigen::Isometry3d> bind;
};

/// One character as its source provides it, before cleaning and preprocessing.
struct SourceCharacter {
  geometry::Character character;  ///< bind pose, file frame and units; name unique in the source
  std::string source;             ///< registry key of the builder, e.g. "zeroad"
  std::string path;               ///< where it came from inside the source
  std::string licence;            ///< SPDX-style, e.g. "CC-BY-SA-3.0"
  std::string attribution;        ///< who made it, for the dataset card
  std::string skeleton;           ///< skeleton family (e.g. "biped", "horse"): grouping, splits
  /// The up direction of the character's frame; preprocessing rotates it to +Y (normalize.hpp),
  /// e.g. +Z for the Quake-lineage formats IQM and ZYM.
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  /// The frame is left-handed (0 A.D.'s game frame, read_pmd.hpp): read as right-handed x, y, z
  /// the character is its own mirror image (0 A.D.'s `_L` joints sit on its right) with every
  /// face wound clockwise seen from outside. Preparation keeps the frame (the methods that read
  /// inside and outside orient the faces first, geometry/orient_outward.hpp); `skinlab export`
  /// mirrors front to back so that another program gets the character as the game shows it, and
  /// so does preparation with `preprocess.right_handed: true` (make_right_handed below).
  bool left_handed = false;
  /// bind[j]: joint j's bind-pose global transform (the frame of `character`), as Animation::bind
  /// but kept whether or not the character has a clip, so that another clip of its skeleton
  /// family can pose it (DenseGATs' corrective task). Empty when the source gives joint positions
  /// only (OBJ + rig text) or an assimp file's bind transforms are not rigid up to a uniform
  /// scale (geometry::ImportedMotion::no_bind).
  std::vector<Eigen::Isometry3d> bind;
  std::vector<Animation> animations;
};

/// Reads a left-handed character (SourceCharacter::left_handed) as the right-handed one it shows:
/// mirrors it front to back (z → −z) in everything that has a position or orientation: the mesh,
/// the joint positions and leaf tips, the bind transforms and every clip's frames and bind
/// (B ↦ M·B·M with M = diag(1, 1, −1), so LBS of the mirrored mesh with the mirrored transforms
/// is the mirror image of LBS before). Mirroring reverses the winding, so faces wound clockwise
/// seen from outside come out counter-clockwise, the glTF and OBJ convention; the weights and the
/// joint order do not change. Clears `left_handed`; a right-handed character is left as it is.
/// Used by `skinlab export` and by preprocessing asked for the right-handed frame
/// (`preprocess.right_handed`, data/preprocess.hpp).
void make_right_handed(SourceCharacter& source);

/// A character a builder could not use, with the reason (reported in the dataset card).
struct Excluded {
  std::string source;
  std::string path;
  std::string reason;
};

class DatasetBuilder {
 public:
  virtual ~DatasetBuilder() = default;
  /// Reads every character of the source. A character that cannot be read or fails validation
  /// goes to `excluded` with its reason; only a source that cannot be read at all (missing
  /// directory, unreadable archive) throws.
  virtual std::vector<SourceCharacter> read(std::vector<Excluded>& excluded) const = 0;
};

}  // namespace skinlab::datasets

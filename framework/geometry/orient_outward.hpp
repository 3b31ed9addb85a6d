#pragma once
/// \file
/// Outward orientation of a mesh's faces, per connected part, for methods that read inside and
/// outside from the winding (normals by the right-hand rule on F's vertex order): Geodesic Voxel
/// Binding's interior test and Maya's requirement of outward-facing normals, Blender bone heat's
/// normal-weighted distance and front-face visibility. Game meshes are not consistent about it:
/// all 88 characters of the dataset prepared from configs/datasets/games.yaml come out of
/// preparation wound clockwise seen from outside (negative signed volume; measured by
/// benchmarks/baselines/binders_bench.cpp, counter inward_characters), the Minetest player
/// (B3D) counter-clockwise.
///
/// Rule: the faces are split into connected parts (faces sharing a vertex). A part's signed
/// volume V = Σ_f (a − c)·((b − c) × (d − c)) / 6 over its faces (a, b, d), with c the mean of
/// the part's vertices, is the enclosed volume (positive when the faces point outwards) for a
/// closed part, and about it for a part with small holes; c makes it independent of where the
/// part lies, which matters only for open parts. A part with V < 0 has all its faces flipped
/// (two indices swapped); whether the faces within a part agree with each other is not checked
/// or changed. Open sheets (V ≈ 0 either way) may go either way.

#include "framework/geometry/mesh.hpp"

namespace skinlab::geometry {

struct OrientReport {
  int parts = 0;          ///< connected parts with at least one face
  int flipped_parts = 0;  ///< parts whose faces were flipped
};

/// `mesh` with the faces of every part of negative signed volume flipped (vertices unchanged,
/// faces in the same order). Requires a valid mesh.
Mesh orient_outward(const Mesh& mesh, OrientReport* report = nullptr);

}  // namespace skinlab::geometry

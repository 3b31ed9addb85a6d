#pragma once
/// \file
/// The references of a 0 A.D. actor (`art/actors/**.xml`) or variant file (`art/variants/**.xml`)
/// that pair meshes with animations. An actor is groups of variants (possibly inside
/// <qualitylevels>); a variant names a mesh (`<mesh>skeletal/horse.dae</mesh>`, stored as
/// art/meshes/skeletal/horse.dae.cached.pmd), animations (`<animation file="quadraped/
/// horse_gallop.dae" name="Run"/>`, stored as art/animation/...dae.cached.psa) and may pull in a
/// variant file (`<variant file="quadraped/horse/base.xml"/>`, under art/variants/), which may
/// pull in others. Format as read by the engine's CObjectBase (source/graphics/ObjectBase.cpp).

#include <string>
#include <vector>

namespace skinlab::datasets::zeroad {

struct ActorAnimation {
  std::string name;  ///< the animation's role, e.g. "Walk", "Idle"
  std::string file;  ///< as written, relative to art/animation/, e.g. "biped/walk.dae"
};

struct ActorRefs {
  std::vector<std::string> meshes;  ///< as written, relative to art/meshes/
  std::vector<ActorAnimation> animations;
  std::vector<std::string> variant_files;  ///< as written, relative to art/variants/
};

/// Collects every mesh, animation and variant-file reference anywhere in the file, in document
/// order; an <animation> without file (a role without a clip) is skipped. Throws Error
/// "source:line: ..." for malformed XML.
ActorRefs read_actor(const std::string& xml, const std::string& source);

}  // namespace skinlab::datasets::zeroad

#pragma once
/// \file
/// 0 A.D.'s skeleton definitions (`art/skeletons/*.xml`), as the COLLADA converter reads them
/// (LoadSkeletonData in source/collada/StdSkeletons.cpp):
///
///     <skeletons>
///       <standard_skeleton id="Biped" title="...">  <bone name="hip"> <bone .../> </bone> ...
///       <skeleton target="Biped" title="..."> <identifier><root>Bip01</root></identifier>
///         <bone name="Bip01"> <target>hip</target> <bone ...> ... </bone> </bone>
///       </skeleton>
///     </skeletons>
///
/// A `standard_skeleton` is the bone tree the game animates; its bones, numbered depth-first in
/// document order, are the bone indices of every PMD mesh and PSA animation converted against
/// it, and the PMD's bone count is the standard skeleton's bone count. A `skeleton` maps the
/// bone names of one authoring tool's rig onto a standard skeleton (a bone without `<target>`
/// inherits its parent's). A standard skeleton may have several top-level bones (e.g. the
/// biped's knee and elbow IK helpers).

#include <string>
#include <vector>

namespace skinlab::datasets::zeroad {

struct StandardSkeleton {
  std::string id;  ///< what target skeletons refer to; not unique across files
  std::string title;
  std::string file;                ///< the XML file it came from
  std::vector<std::string> names;  ///< #B bone names, depth-first document order (PMD order)
  std::vector<int> parents;        ///< #B parent bone index, -1 for a top-level bone
};

struct TargetSkeleton {
  std::string title;
  std::string target;  ///< id of the standard skeleton it maps onto
  std::string root;    ///< identifier: the rig's root bone name
  std::string file;
  std::vector<std::string> names;    ///< the rig's bone names, depth-first
  std::vector<std::string> targets;  ///< the standard bone each maps to (inherited if absent)
};

struct SkeletonFile {
  std::vector<StandardSkeleton> standard;
  std::vector<TargetSkeleton> mapped;
};

/// Parses one skeleton XML file. Throws Error "source:line: ..." for malformed XML, a root
/// other than <skeletons>, a standard skeleton without id or bones, a bone without name, a
/// duplicate bone name in one standard skeleton, a target skeleton without target or
/// identifier root, and a `<target>` naming no bone of a standard skeleton of the same id in
/// this file.
SkeletonFile read_skeletons(const std::string& xml, const std::string& source);

}  // namespace skinlab::datasets::zeroad

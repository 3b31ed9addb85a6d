#include "datasets/zeroad/zeroad.hpp"

#include <algorithm>
#include <map>
#include <memory>
#include <set>

#include "datasets/zeroad/match_skeleton.hpp"
#include "datasets/zeroad/package.hpp"
#include "datasets/zeroad/read_actor.hpp"
#include "datasets/zeroad/read_pmd.hpp"
#include "datasets/zeroad/read_psa.hpp"
#include "datasets/zeroad/read_skeletons.hpp"
#include "framework/core/registry.hpp"

namespace skinlab::datasets {

using namespace zeroad;

namespace {

constexpr const char* kSource = "zeroad";
constexpr const char* kMeshDir = "art/meshes/";
constexpr const char* kSkeletalDir = "art/meshes/skeletal/";
constexpr const char* kPmdSuffix = ".dae.cached.pmd";
constexpr const char* kPsaSuffix = ".dae.cached.psa";
constexpr int kMaxClipsForMatching = 8;

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// "skeletal/horse.dae" → "art/meshes/skeletal/horse.dae.cached.pmd"
std::string mesh_entry(const std::string& ref) {
  std::string stem = ends_with(ref, ".dae") ? ref.substr(0, ref.size() - 4) : ref;
  return kMeshDir + stem + kPmdSuffix;
}
/// "quadraped/horse_gallop.dae" → "art/animation/quadraped/horse_gallop.dae.cached.psa"
std::string clip_entry(const std::string& ref) {
  std::string stem = ends_with(ref, ".dae") ? ref.substr(0, ref.size() - 4) : ref;
  return "art/animation/" + stem + kPsaSuffix;
}

/// Meshes and animations of one actor, following variant files (cycles and missing files are
/// ignored: the engine treats a missing variant file as an error of that actor only).
void collect(const Package& pkg, const std::string& entry, std::set<std::string>& visited,
             std::map<std::string, ActorRefs>& cache, ActorRefs& out) {
  if (!visited.insert(entry).second || !pkg.contains(entry)) return;
  auto it = cache.find(entry);
  if (it == cache.end()) it = cache.emplace(entry, read_actor(pkg.read(entry), entry)).first;
  const ActorRefs& refs = it->second;
  out.meshes.insert(out.meshes.end(), refs.meshes.begin(), refs.meshes.end());
  out.animations.insert(out.animations.end(), refs.animations.begin(), refs.animations.end());
  for (const auto& v : refs.variant_files) collect(pkg, "art/variants/" + v, visited, cache, out);
}

}  // namespace

ZeroAdBuilder::Options ZeroAdBuilder::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "dataset 'zeroad'");
  f.optional("path", o.path).check(!o.path.empty(), "path", "must not be empty");
  f.optional("animations", o.animations);
  f.optional("max_animations_per_character", o.max_animations_per_character)
      .check(o.max_animations_per_character >= 0, "max_animations_per_character",
             "must be >= 0 (0: all)");
  f.finish();
  return o;
}

std::vector<SourceCharacter> ZeroAdBuilder::read(std::vector<Excluded>& excluded) const {
  const Package pkg(options_.path);
  const auto exclude = [&](const std::string& path, const std::string& reason) {
    excluded.push_back({kSource, path, reason});
  };

  std::vector<StandardSkeleton> skeletons;
  for (const auto& entry : pkg.list("art/skeletons/", ".xml")) {
    try {
      auto file = read_skeletons(pkg.read(entry), entry);
      for (auto& s : file.standard) skeletons.push_back(std::move(s));
    } catch (const Error& e) {
      exclude(entry, std::string("skeleton file: ") + e.what());
    }
  }

  // mesh entry → clip entries (first use order, unique) and the clips' roles
  std::map<std::string, std::vector<std::string>> mesh_clips;
  {
    std::map<std::string, ActorRefs> cache;
    for (const auto& actor : pkg.list("art/actors/", ".xml")) {
      ActorRefs refs;
      std::set<std::string> visited;
      try {
        collect(pkg, actor, visited, cache, refs);
      } catch (const Error& e) {
        exclude(actor, std::string("actor file: ") + e.what());
        continue;
      }
      for (const auto& m : refs.meshes) {
        auto& clips = mesh_clips[mesh_entry(m)];
        for (const auto& a : refs.animations) {
          const std::string c = clip_entry(a.file);
          if (std::find(clips.begin(), clips.end(), c) == clips.end()) clips.push_back(c);
        }
      }
    }
  }

  std::map<std::string, std::shared_ptr<const Psa>> clip_cache;
  const auto load_clip = [&](const std::string& entry) -> std::shared_ptr<const Psa> {
    auto it = clip_cache.find(entry);
    if (it != clip_cache.end()) return it->second;
    std::shared_ptr<const Psa> psa;
    if (pkg.contains(entry)) {
      try {
        psa = std::make_shared<const Psa>(read_psa(pkg.read(entry), entry));
      } catch (const Error&) {
        psa = nullptr;  // a broken clip is skipped; the mesh stays usable
      }
    }
    return clip_cache[entry] = psa;
  };

  std::vector<SourceCharacter> out;
  std::set<std::string> names;
  for (const auto& entry : pkg.list(kSkeletalDir, ".pmd")) {
    Pmd pmd;
    try {
      pmd = read_pmd(pkg.read(entry), entry);
    } catch (const Error& e) {
      exclude(entry, e.what());
      continue;
    }
    if (pmd.num_bones() == 0) {
      exclude(entry, "static mesh: no bones");
      continue;
    }
    std::set<int> used;
    for (Eigen::Index v = 0; v < pmd.bone_indices.rows(); ++v)
      for (int k = 0; k < 4; ++k)
        if (pmd.bone_indices(v, k) >= 0 && pmd.bone_weights(v, k) > 0)
          used.insert(pmd.bone_indices(v, k));
    if (used.size() <= 1) {
      exclude(entry, "rigid: all " + std::to_string(pmd.positions.rows()) +
                         " vertices follow one bone of " + std::to_string(pmd.num_bones()));
      continue;
    }

    // Clips of the actors using this mesh, with its bone count, in actor order.
    std::vector<std::shared_ptr<const Psa>> clips;
    std::vector<std::string> clip_names;
    auto mc = mesh_clips.find(entry);
    if (mc != mesh_clips.end()) {
      const std::size_t wanted =
          options_.animations && options_.max_animations_per_character == 0
              ? mc->second.size()
              : std::max<std::size_t>(
                    kMaxClipsForMatching,
                    options_.animations ? options_.max_animations_per_character : 0);
      for (const auto& c : mc->second) {
        if (clips.size() >= wanted) break;
        auto psa = load_clip(c);
        if (!psa || psa->num_bones != pmd.num_bones() || psa->frames.empty()) continue;
        clips.push_back(psa);
        clip_names.push_back(c);
      }
    }
    std::vector<const Psa*> for_matching;
    for (std::size_t i = 0; i < clips.size() && i < kMaxClipsForMatching; ++i)
      for_matching.push_back(clips[i].get());
    const SkeletonMatch match = match_skeleton(pmd, skeletons, for_matching);
    if (match.index < 0) {
      exclude(entry, "no skeleton: " + match.reason);
      continue;
    }
    const StandardSkeleton& std_skel = skeletons[match.index];

    std::string rel = entry.substr(std::string(kSkeletalDir).size());
    rel = rel.substr(0, rel.size() - std::string(kPmdSuffix).size());
    std::string name = rel.substr(rel.find_last_of('/') + 1);
    if (names.count(name)) {
      name = rel;
      std::replace(name.begin(), name.end(), '/', '_');
    }

    SourceCharacter sc;
    sc.source = kSource;
    sc.path = entry;
    sc.licence = "CC-BY-SA-3.0";
    sc.attribution = "Wildfire Games (0 A.D.)";
    sc.skeleton = std_skel.id;
    sc.left_handed = true;  // the game's frame (read_pmd.hpp)
    geometry::Character& ch = sc.character;
    ch.name = name;
    ch.mesh.V = pmd.positions;
    ch.mesh.F = pmd.faces;
    const int nb = pmd.num_bones();
    ch.skeleton.names = std_skel.names;
    ch.skeleton.parents = std_skel.parents;
    int first_root = -1;
    for (int j = 0; j < nb; ++j) {
      if (ch.skeleton.parents[j] >= 0) continue;
      if (first_root < 0)
        first_root = j;
      else
        ch.skeleton.parents[j] = first_root;
    }
    ch.skeleton.positions.resize(nb, 3);
    for (int j = 0; j < nb; ++j)
      ch.skeleton.positions.row(j) = pmd.bind[j].translation().transpose();
    sc.bind = pmd.bind;
    std::vector<Eigen::Triplet<double>> triplets;
    for (Eigen::Index v = 0; v < pmd.bone_indices.rows(); ++v)
      for (int k = 0; k < 4; ++k)
        if (pmd.bone_indices(v, k) >= 0)
          triplets.emplace_back(static_cast<int>(v), pmd.bone_indices(v, k),
                                pmd.bone_weights(v, k));
    ch.weights.resize(pmd.positions.rows(), nb);
    ch.weights.setFromTriplets(triplets.begin(), triplets.end());  // sums repeated bones
    try {
      ch.validate();
    } catch (const Error& e) {
      exclude(entry, e.what());
      continue;
    }

    if (options_.animations) {
      for (std::size_t i = 0; i < clips.size(); ++i) {
        if (options_.max_animations_per_character > 0 &&
            static_cast<int>(sc.animations.size()) >= options_.max_animations_per_character)
          break;
        Animation a;
        const std::string& c = clip_names[i];
        a.name = c.substr(
            std::string("art/animation/").size(),
            c.size() - std::string("art/animation/").size() - std::string(kPsaSuffix).size());
        a.fps = 1000.0 / clips[i]->frame_time_ms;
        a.bind = pmd.bind;
        a.frames = clips[i]->frames;
        sc.animations.push_back(std::move(a));
      }
    }
    names.insert(name);
    out.push_back(std::move(sc));
  }
  return out;
}

}  // namespace skinlab::datasets

SKINLAB_REGISTER(dataset, zeroad, skinlab::datasets::ZeroAdBuilder);

#include "datasets/ogre/ogre.hpp"

#include <fnmatch.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>

#include "datasets/byte_reader.hpp"
#include "datasets/ogre/ogre_file.hpp"
#include "datasets/rigged_model.hpp"
#include "framework/core/registry.hpp"

namespace skinlab::datasets {

namespace fs = std::filesystem;

namespace ogre {

void TreeOptions::read(config::Fields& f, const std::string& owner) {
  f.optional("licence", licence);
  f.optional("attribution", attribution);
  f.optional("animations", animations);
  f.optional("max_animations_per_character", max_animations_per_character);
  f.optional("fps", fps);
  f.optional("join_weighted_roots", join_weighted_roots);
  f.optional("max_unweighted_fraction", max_unweighted_fraction);
  f.optional("up", up);
  const config::Node credit_list = f.section("credits");
  if (credit_list.exists() && !credit_list.is_null()) {
    if (!credit_list.is_sequence()) credit_list.fail("expected a list of {files, licence, attribution}");
    for (std::size_t i = 0; i < credit_list.size(); ++i) {
      Credit c;
      config::Fields cf(credit_list[i], owner + " credit", {});
      cf.required("files", c.files);
      cf.required("licence", c.licence);
      cf.optional("attribution", c.attribution);
      cf.finish();
      credits.push_back(c);
    }
  }
  const config::Node exclusions = f.section("exclude");
  if (exclusions.exists() && !exclusions.is_null()) {
    if (!exclusions.is_map()) exclusions.fail("expected a map of path glob → reason");
    for (const auto& glob : exclusions.keys()) exclude.emplace_back(glob, exclusions[glob].as<std::string>());
  }
  f.check(max_animations_per_character >= 0, "max_animations_per_character", "must be ≥ 0");
  f.check(fps > 0, "fps", "must be positive");
  f.check(up.size() == 3 && (up[0] != 0 || up[1] != 0 || up[2] != 0), "up",
          "must be a non-zero vector [x, y, z]");
  f.check(max_unweighted_fraction >= 0 && max_unweighted_fraction <= 1,
          "max_unweighted_fraction", "must be in [0, 1]");
}

}  // namespace ogre

OgreBuilder::Options OgreBuilder::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "dataset 'ogre'");
  o.source = RepositorySource::from(f, node);
  o.read(f, "dataset 'ogre'");
  f.finish();
  return o;
}

fs::path OgreBuilder::root() const { return options_.source.root("ogre"); }

namespace {

std::string ogre_lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool glob_matches(const std::string& glob, const std::string& text) {
  return ::fnmatch(glob.c_str(), text.c_str(), 0) == 0;
}

/// Joint order with parents first: the file's handle order when it already is, else
/// depth-first from the roots in handle order. order[k] = handle of joint k.
std::vector<int> parents_first_order(const ogre::OgreSkeleton& s) {
  const int n = static_cast<int>(s.bones.size());
  bool sorted = true;
  for (int b = 0; b < n; ++b) sorted = sorted && s.bones[b].parent < b;
  std::vector<int> order;
  if (sorted) {
    for (int b = 0; b < n; ++b) order.push_back(b);
    return order;
  }
  std::vector<std::vector<int>> children(n);
  for (int b = 0; b < n; ++b) {
    if (s.bones[b].parent >= 0) children[s.bones[b].parent].push_back(b);
  }
  std::function<void(int)> visit = [&](int b) {
    order.push_back(b);
    for (int c : children[b]) visit(c);
  };
  for (int b = 0; b < n; ++b) {
    if (s.bones[b].parent < 0) visit(b);
  }
  return order;
}

Eigen::Isometry3d isometry(const Eigen::Vector3d& position, const Eigen::Quaterniond& rotation) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation.normalized().toRotationMatrix();
  T.translation() = position;
  return T;
}

/// Weight statistics of one mesh, for the log.
struct WeightStats {
  int renormalised = 0;   ///< vertices whose stored weights did not sum to 1 (±1e-3)
  int trimmed = 0;        ///< vertices with more than 4 bones, cut to their 4 largest
  int merged = 0;         ///< repeated (vertex, bone) assignments summed
  int dropped_free = 0;   ///< vertices without weight and without triangle, removed
  int dropped_unweighted = 0;  ///< vertices without weight used by triangles, removed
  int dropped_faces = 0;       ///< triangles removed with them
};

/// Name of the weightless joint added above several weighted root bones.
const std::string kOriginJoint = "ogre_origin";

/// The directory part of a tree path ("" at the root).
std::string tree_dir(const std::string& path) {
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash);
}

std::string tree_filename(const std::string& path) {
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string tree_extension(const std::string& path) {
  const std::string name = tree_filename(path);
  const auto dot = name.rfind('.');
  return dot == std::string::npos ? std::string() : ogre_lower(name.substr(dot));
}

}  // namespace

std::vector<SourceCharacter> OgreBuilder::read(std::vector<Excluded>& excluded) const {
  const fs::path dir = root();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw IoError(dir.string() + ": dataset 'ogre': not a readable directory" +
                  (options_.source.repository.empty()
                       ? std::string()
                       : " (repository " + options_.source.repository + " at " +
                             options_.source.commit + ")"));
  }
  std::vector<fs::path> files;
  try {
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
      const std::string ext = ogre_lower(e.path().extension().string());
      if (e.is_regular_file() && (ext == ".mesh" || ext == ".skeleton")) files.push_back(e.path());
    }
  } catch (const fs::filesystem_error& e) {
    throw IoError(dir.string() + ": dataset 'ogre': cannot list directory: " + e.what());
  }
  std::sort(files.begin(), files.end());  // path order (by component)
  ogre::Tree tree;
  tree.source = options_.source.label("ogre");
  tree.where = dir.string();
  for (const fs::path& file : files) {
    tree.files.push_back({file.lexically_relative(dir).generic_string(),
                          [file] { return read_binary_file(file); }});
  }
  return ogre::read_tree(tree, options_, excluded);
}

std::vector<SourceCharacter> ogre::read_tree(const Tree& tree, const TreeOptions& options,
                                             std::vector<Excluded>& excluded) {
  std::map<std::string, const TreeFile*> by_path;
  std::map<std::string, std::vector<std::string>> skeletons_by_name;  // lower-case file name
  std::vector<const TreeFile*> meshes;
  for (const TreeFile& file : tree.files) {
    const std::string ext = tree_extension(file.path);
    by_path.emplace(file.path, &file);
    if (ext == ".mesh") meshes.push_back(&file);
    if (ext == ".skeleton") skeletons_by_name[ogre_lower(tree_filename(file.path))].push_back(file.path);
  }
  for (auto& [name, paths] : skeletons_by_name) std::sort(paths.begin(), paths.end());

  // Parsed skeletons by path (several meshes share one); a parse error is kept as its message.
  std::map<std::string, std::pair<std::shared_ptr<OgreSkeleton>, std::string>> skeleton_cache;
  auto load_skeleton = [&](const std::string& path) {
    auto it = skeleton_cache.find(path);
    if (it == skeleton_cache.end()) {
      std::pair<std::shared_ptr<OgreSkeleton>, std::string> entry;
      try {
        entry.first = std::make_shared<OgreSkeleton>(parse_skeleton(by_path.at(path)->load(), path));
      } catch (const Error& e) {
        entry.second = e.what();
      }
      it = skeleton_cache.emplace(path, entry).first;
    }
    if (!it->second.first) throw IoError(it->second.second);
    return it->second.first;
  };
  // As OGRE's resource groups find it: next to the mesh, then case-insensitively next to it,
  // then by its (case-insensitive) file name anywhere, which must be unique.
  auto resolve_skeleton = [&](const std::string& rel, const std::string& link) -> std::string {
    const std::string dir = tree_dir(rel);
    const std::string next = fs::path(dir.empty() ? link : dir + "/" + link).lexically_normal().generic_string();
    if (by_path.count(next)) return next;
    const std::string wanted = ogre_lower(tree_filename(fs::path(link).generic_string()));
    for (const auto& [path, file] : by_path) {
      if (tree_dir(path) == dir && ogre_lower(tree_filename(path)) == wanted) return path;
    }
    const auto found = skeletons_by_name.find(wanted);
    if (found == skeletons_by_name.end()) {
      throw IoError(rel + ": its skeleton '" + link + "' is not next to it nor anywhere under " +
                    tree.where);
    }
    if (found->second.size() > 1) {
      std::string list;
      for (const auto& p : found->second) list += " " + p;
      throw IoError(rel + ": its skeleton '" + link + "' is not next to it and several files " +
                    "elsewhere have that name:" + list);
    }
    return found->second.front();
  };

  std::vector<SourceCharacter> out;
  for (const TreeFile* file : meshes) {
    const std::string& rel = file->path;
    const auto excluded_by = std::find_if(options.exclude.begin(), options.exclude.end(),
                                          [&](const auto& e) { return glob_matches(e.first, rel); });
    if (excluded_by != options.exclude.end()) {
      excluded.push_back({tree.source, rel, "excluded by the config (" + excluded_by->first + "): " + excluded_by->second});
      continue;
    }
    try {
      const OgreMesh mesh = parse_mesh(file->load(), rel);
      if (mesh.skeleton_link.empty()) {
        throw geometry::GeometryError(rel + ": a static mesh (no skeleton link): a prop or an "
                                      "attachment, not a skinned character");
      }
      if (mesh.assignments.empty()) {
        throw geometry::GeometryError(rel + ": links skeleton '" + mesh.skeleton_link +
                                      "' but has no bone assignments");
      }
      const std::string skeleton_file = resolve_skeleton(rel, mesh.skeleton_link);
      const auto skeleton = load_skeleton(skeleton_file);
      const int num_bones = static_cast<int>(skeleton->bones.size());

      // Weights as OGRE's engine uses them.
      const int nv = static_cast<int>(mesh.V.rows());
      std::vector<std::map<int, double>> per_vertex(nv);
      WeightStats stats;
      for (const auto& a : mesh.assignments) {
        if (a.bone >= num_bones) {
          throw geometry::GeometryError(rel + ": vertex " + std::to_string(a.vertex) +
                                        " is assigned to bone " + std::to_string(a.bone) + ", but " +
                                        tree_filename(skeleton_file) + " has " +
                                        std::to_string(num_bones) + " bones");
        }
        if (a.weight <= 0) continue;
        auto [it, fresh] = per_vertex[a.vertex].emplace(a.bone, a.weight);
        if (!fresh) {
          it->second += a.weight;
          ++stats.merged;
        }
      }
      std::vector<bool> used(nv, false);
      for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
        for (int k = 0; k < 3; ++k) used[mesh.F(f, k)] = true;
      }
      // Vertices without assignment: OGRE warns they "transform to wrong position" when
      // animated. Unused ones are dropped; a few used ones are dropped with their triangles.
      std::vector<bool> broken(nv, false);
      int unweighted_used = 0;
      for (int v = 0; v < nv; ++v) {
        if (!per_vertex[v].empty()) continue;
        if (used[v]) {
          broken[v] = true;
          ++unweighted_used;
        } else {
          ++stats.dropped_free;
        }
      }
      if (unweighted_used > options.max_unweighted_fraction * nv) {
        throw geometry::GeometryError(
            rel + ": " + std::to_string(unweighted_used) + " of " + std::to_string(nv) +
            " vertices used by triangles have no bone assignment (more than " +
            std::to_string(options.max_unweighted_fraction) + " of the vertices)");
      }
      std::vector<Eigen::Vector3i> faces;
      for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
        const Eigen::Vector3i t = mesh.F.row(f).transpose();
        if (broken[t[0]] || broken[t[1]] || broken[t[2]]) {
          ++stats.dropped_faces;
        } else {
          faces.push_back(t);
        }
      }
      stats.dropped_unweighted = unweighted_used;
      std::vector<int> new_vertex(nv, -1);
      int kept_vertices = 0;
      for (int v = 0; v < nv; ++v) {
        if (!per_vertex[v].empty()) new_vertex[v] = kept_vertices++;
      }

      // Joints: the bones with parents first, and when several root bones carry weight, a
      // weightless joint at the model origin above them (the entity's scene node, which OGRE
      // makes the parent of every root bone).
      const std::vector<int> order = parents_first_order(*skeleton);
      std::vector<double> subtree(num_bones, 0.0);
      for (int v = 0; v < nv; ++v) {
        for (const auto& [bone, weight] : per_vertex[v]) subtree[bone] += weight;
      }
      for (int k = num_bones - 1; k >= 0; --k) {
        const int p = skeleton->bones[order[k]].parent;
        if (p >= 0) subtree[p] += subtree[order[k]];
      }
      int weighted_roots = 0;
      for (int b = 0; b < num_bones; ++b) weighted_roots += skeleton->bones[b].parent < 0 && subtree[b] > 0;
      const bool origin = weighted_roots > 1 && options.join_weighted_roots;
      const int first = origin ? 1 : 0;  // model joint of order[0]
      std::vector<int> joint_of(num_bones);
      for (int k = 0; k < num_bones; ++k) joint_of[order[k]] = first + k;
      const BindPose bind = derive_bind_pose(*skeleton);

      RiggedModel model;
      if (tree.name) {
        model.name = tree.name(rel);
      } else {
        model.name = fs::path(rel).replace_extension().generic_string();
        std::replace(model.name.begin(), model.name.end(), '/', '.');
      }
      if (origin) {
        model.joint_names.push_back(kOriginJoint);
        model.parents.push_back(-1);
        model.bind.push_back(Eigen::Isometry3d::Identity());
      }
      for (int k = 0; k < num_bones; ++k) {
        const int h = order[k];
        const OgreBone& b = skeleton->bones[h];
        if (origin && b.name == kOriginJoint) {
          throw geometry::GeometryError(rel + ": a bone is named '" + kOriginJoint +
                                        "', the name of the joint added above its roots");
        }
        model.joint_names.push_back(b.name);
        model.parents.push_back(b.parent >= 0 ? joint_of[b.parent] : origin && subtree[h] > 0 ? 0 : -1);
        model.bind.push_back(isometry(bind.position[h], bind.orientation[h]));
      }
      const int num_joints = static_cast<int>(model.joint_names.size());
      model.V.resize(kept_vertices, 3);
      std::vector<Eigen::Triplet<double>> triplets;
      for (int v = 0; v < nv; ++v) {
        if (new_vertex[v] < 0) continue;
        model.V.row(new_vertex[v]) = mesh.V.row(v);
        std::vector<std::pair<double, int>> w;  // (weight, bone)
        double total = 0;
        for (const auto& [bone, weight] : per_vertex[v]) {
          w.emplace_back(weight, bone);
          total += weight;
        }
        if (w.size() > 4) {  // OGRE_MAX_BLEND_WEIGHTS: keep the 4 largest
          ++stats.trimmed;
          std::sort(w.begin(), w.end(), [](const auto& a, const auto& b) {
            return a.first != b.first ? a.first > b.first : a.second < b.second;
          });
          w.resize(4);
        }
        if (std::abs(total - 1.0) > 1e-3) ++stats.renormalised;
        double kept_total = 0;
        for (const auto& [weight, bone] : w) kept_total += weight;
        for (const auto& [weight, bone] : w) {
          triplets.emplace_back(new_vertex[v], joint_of[bone], weight / kept_total);
        }
      }
      model.W.resize(kept_vertices, num_joints);
      model.W.setFromTriplets(triplets.begin(), triplets.end());
      model.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
      for (std::size_t f = 0; f < faces.size(); ++f) {
        for (int k = 0; k < 3; ++k) model.F(static_cast<Eigen::Index>(f), k) = new_vertex[faces[f][k]];
      }

      SourceRig rig = to_source_rig(model);

      SourceCharacter sc;
      sc.source = tree.source;
      sc.path = rel;
      sc.skeleton = fs::path(tree_filename(skeleton_file)).stem().string();
      sc.up = Eigen::Vector3d(options.up[0], options.up[1], options.up[2]).normalized();
      sc.licence = options.licence;
      sc.attribution = options.attribution;
      const std::string filename = tree_filename(rel);
      for (const TreeOptions::Credit& c : options.credits) {
        if (glob_matches(c.files, rel) || glob_matches(c.files, filename)) {
          sc.licence = c.licence;
          sc.attribution = c.attribution;
          break;
        }
      }

      int clips_scaled = 0;
      if (options.animations) {
        for (const auto& clip : skeleton->animations) {
          if (static_cast<int>(sc.animations.size()) >= options.max_animations_per_character) break;
          const int frames = static_cast<int>(std::floor(clip.length * options.fps + 1e-9)) + 1;
          std::vector<Transforms> global(frames);
          bool rigid = true;
          for (int f = 0; f < frames && rigid; ++f) {
            const BindPose pose = sample_animation(*skeleton, clip, f / options.fps);
            global[f].assign(num_joints, Eigen::Isometry3d::Identity());
            for (int k = 0; k < num_bones; ++k) {
              const int h = order[k];
              global[f][first + k] = isometry(pose.position[h], pose.orientation[h]);
            }
            for (int j : rig.kept) {
              if (j < first) continue;  // the origin joint
              const int h = order[j - first];
              if ((pose.scale[h] - bind.scale[h]).cwiseAbs().maxCoeff() >
                  1e-4 * std::max(1.0, bind.scale[h].cwiseAbs().maxCoeff())) {
                rigid = false;
                break;
              }
            }
          }
          if (!rigid) {
            ++clips_scaled;
            continue;
          }
          sc.animations.push_back(make_animation(clip.name, options.fps, global, rig));
        }
      }
      spdlog::info(
          "{}: {}: {} vertices, {} triangles, {} of {} bones kept{}, skeleton {}; weights: {} "
          "vertices renormalised, {} cut to 4 bones, {} repeated assignments summed; dropped: {} "
          "free vertices, {} unweighted vertices with {} triangles; {} of {} clips kept{}",
          tree.source, rel, rig.character.mesh.V.rows(), rig.character.mesh.F.rows(), rig.kept.size() - first,
          num_bones, origin ? " under an added '" + kOriginJoint + "' joint (" + std::to_string(weighted_roots) + " weighted roots)" : "",
          skeleton_file, stats.renormalised,
          stats.trimmed, stats.merged, stats.dropped_free, stats.dropped_unweighted,
          stats.dropped_faces, sc.animations.size(),
          skeleton->animations.size(),
          clips_scaled > 0 ? " (" + std::to_string(clips_scaled) + " change a joint's scale: left out)" : "");
      sc.bind = rig.bind;
      sc.character = std::move(rig.character);
      out.push_back(std::move(sc));
    } catch (const std::exception& e) {  // Error, and e.g. bad_alloc on absurd counts
      excluded.push_back({tree.source, rel, e.what()});
    }
  }
  return out;
}

}  // namespace skinlab::datasets

SKINLAB_REGISTER(dataset, ogre, skinlab::datasets::OgreBuilder);

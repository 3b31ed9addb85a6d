#include "datasets/folder/folder.hpp"

#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>

#include "datasets/cube2/iqm.hpp"
#include "datasets/rigged_model.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/geometry/import_character.hpp"
#include "framework/geometry/rig_io.hpp"

namespace skinlab::datasets {

namespace fs = std::filesystem;

namespace {

std::string strip_slashes(std::string p) {
  while (!p.empty() && p.front() == '/') p.erase(p.begin());
  return p;
}

}  // namespace

Folder::Options Folder::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "dataset 'folder'");
  o.source = RepositorySource::from(f, node);
  f.optional("licence", o.licence);
  f.optional("attribution", o.attribution);
  f.optional("skeleton", o.skeleton);
  f.optional("prefix", o.prefix);
  f.optional("recursive", o.recursive);
  f.optional("include", o.include);
  const config::Node exclude = f.section("exclude");
  if (exclude.exists() && !exclude.is_null()) {
    if (!exclude.is_map()) exclude.fail("expected a map of relative path or glob → reason");
    for (const auto& pattern : exclude.keys()) {
      o.exclude.emplace_back(strip_slashes(pattern), exclude[pattern].as<std::string>());
      if (o.exclude.back().second.empty()) exclude[pattern].fail("the reason must not be empty");
    }
  }
  f.optional("animations", o.animations);
  f.optional("max_animations_per_character", o.max_animations_per_character);
  f.optional("fps", o.fps);
  f.check(o.max_animations_per_character >= 0, "max_animations_per_character", "must be ≥ 0");
  f.check(std::isfinite(o.fps) && o.fps > 0, "fps", "must be a positive number of frames per second");
  for (const auto& p : o.include) f.check(!p.empty(), "include", "a pattern must not be empty");
  for (auto& p : o.include) p = strip_slashes(p);
  f.finish();
  return o;
}

bool glob_match(const std::string& pattern, const std::string& path) {
  // Recursive matcher over C strings; patterns are short, so backtracking is cheap.
  struct M {
    static bool match(const char* p, const char* s) {
      while (*p != '\0') {
        if (p[0] == '*' && p[1] == '*') {
          p += 2;
          if (*p == '/') {  // "**/": zero or more whole directories
            ++p;
            if (match(p, s)) return true;
            for (const char* t = s; *t != '\0'; ++t) {
              if (*t == '/' && match(p, t + 1)) return true;
            }
            return false;
          }
          for (const char* t = s;; ++t) {  // "**": any run, '/' included
            if (match(p, t)) return true;
            if (*t == '\0') return false;
          }
        }
        if (*p == '*') {
          ++p;
          for (const char* t = s;; ++t) {
            if (match(p, t)) return true;
            if (*t == '\0' || *t == '/') return false;
          }
        }
        if (*p == '?') {
          if (*s == '\0' || *s == '/') return false;
        } else if (*p != *s) {
          return false;
        }
        ++p;
        ++s;
      }
      return *s == '\0';
    }
  };
  return M::match(pattern.c_str(), path.c_str());
}

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool is_assimp_character(const std::string& ext) {
  static const std::set<std::string> kExtensions = {".fbx", ".gltf", ".glb", ".dae",
                                                    ".b3d", ".smd",  ".x",   ".md5mesh"};
  return kExtensions.count(ext) > 0;
}

/// Rotates V, joint positions and the joints' bind and clip transforms so that `up` becomes +Y
/// (the smallest rotation; 180° about X for −Y), as NormalizeOptions::source_up would. The
/// transforms are conjugated, T ↦ R·T·R⁻¹ (as preprocessing conjugates by its similarity), so
/// that (R·F·R⁻¹)(R·B·R⁻¹)⁻¹ = R·(F·B⁻¹)·R⁻¹ poses the rotated mesh exactly as F·B⁻¹ posed the
/// original, and bind translations stay the rotated joint positions.
void rotate_to_y_up(geometry::Character& c, geometry::ImportedMotion& motion,
                    const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  if ((u - Eigen::Vector3d::UnitY()).norm() < 1e-12) return;
  const Eigen::Matrix3d R =
      (u + Eigen::Vector3d::UnitY()).norm() < 1e-12
          ? Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix()
          : Eigen::Quaterniond::FromTwoVectors(u, Eigen::Vector3d::UnitY()).toRotationMatrix();
  c.mesh.V = c.mesh.V * R.transpose();
  c.skeleton.positions = c.skeleton.positions * R.transpose();
  Eigen::Isometry3d rotation = Eigen::Isometry3d::Identity();
  rotation.linear() = R;
  const Eigen::Isometry3d inverse = rotation.inverse();
  for (auto& T : motion.bind) T = rotation * T * inverse;
  for (auto& clip : motion.clips) {
    for (auto& frame : clip.frames) {
      for (auto& T : frame) T = rotation * T * inverse;
    }
  }
}

/// Divides every weight row by its sum; returns how many rows were off 1 by more than 1e-3
/// (the tolerance of geometry::WeightCheck) and the largest such deviation.
std::pair<int, double> renormalise(geometry::SparseWeights& W) {
  int off = 0;
  double worst = 0;
  for (Eigen::Index v = 0; v < W.outerSize(); ++v) {
    double sum = 0;
    for (geometry::SparseWeights::InnerIterator it(W, v); it; ++it) sum += it.value();
    if (sum <= 0) continue;  // rejected by validation before this
    if (std::abs(sum - 1) > 1e-3) {
      ++off;
      worst = std::max(worst, std::abs(sum - 1));
    }
    for (geometry::SparseWeights::InnerIterator it(W, v); it; ++it) it.valueRef() /= sum;
  }
  return {off, worst};
}

/// `message` with every occurrence of `root/` removed, so that reasons name files relative to
/// the scanned directory (the same on every machine).
std::string relative_message(std::string message, const std::string& root) {
  const std::string prefix = root + "/";
  for (auto at = message.find(prefix); at != std::string::npos; at = message.find(prefix, at)) {
    message.erase(at, prefix.size());
  }
  return message;
}

}  // namespace

fs::path Folder::root() const { return options_.source.root("folder"); }

std::vector<SourceCharacter> Folder::read(std::vector<Excluded>& excluded) const {
  fs::path dir = root().lexically_normal();
  if (!dir.has_filename() && dir.has_parent_path()) dir = dir.parent_path();  // no trailing '/'
  const std::string label = options_.source.label("folder");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw IoError(dir.string() + ": dataset 'folder'" +
                  (options_.source.repository.empty() ? std::string()
                                               : " (repository " + options_.source.repository + ")") +
                  ": not a readable directory");
  }
  const bool recursive = options_.recursive || !options_.include.empty();
  std::vector<fs::path> files;
  try {
    if (recursive) {
      for (const auto& e : fs::recursive_directory_iterator(dir)) {
        if (e.is_regular_file()) files.push_back(e.path());
      }
    } else {
      for (const auto& e : fs::directory_iterator(dir)) {
        if (e.is_regular_file()) files.push_back(e.path());
      }
    }
  } catch (const fs::filesystem_error& e) {
    throw IoError(dir.string() + ": dataset 'folder': cannot list directory: " + e.what());
  }
  std::sort(files.begin(), files.end());

  std::vector<bool> include_used(options_.include.size(), false);
  std::vector<bool> exclude_used(options_.exclude.size(), false);
  std::vector<SourceCharacter> out;
  std::set<std::string> names;
  int renormalised_files = 0;
  long renormalised_vertices = 0;
  const std::string root_text = dir.string();
  for (const auto& file : files) {
    const std::string ext = lower(file.extension().string());
    const bool obj = ext == ".obj";
    const bool iqm = ext == ".iqm";
    if (!obj && !iqm && !is_assimp_character(ext)) continue;
    const std::string relative = fs::relative(file, dir).generic_string();
    if (relative.rfind(".git/", 0) == 0) continue;
    if (!options_.include.empty()) {
      bool included = false;
      for (std::size_t i = 0; i < options_.include.size(); ++i) {
        if (glob_match(options_.include[i], relative)) included = include_used[i] = true;
      }
      if (!included) continue;
    }
    const std::string* reason = nullptr;
    for (std::size_t i = 0; i < options_.exclude.size(); ++i) {
      if (glob_match(options_.exclude[i].first, relative)) {
        exclude_used[i] = true;
        if (reason == nullptr) reason = &options_.exclude[i].second;
      }
    }
    if (reason != nullptr) {
      excluded.push_back({label, relative, *reason});
      continue;
    }
    try {
      geometry::Character c;
      SourceCharacter s;
      // Rows are renormalised below, where they are counted.
      const geometry::WeightCheck keep_sums{std::numeric_limits<double>::infinity(), false};
      if (obj) {
        const fs::path rig = file.parent_path() / (file.stem().string() + "_rig.txt");
        if (!fs::exists(rig)) {
          throw IoError(relative + ": OBJ mesh without its RigNet rig file " +
                        rig.filename().string());
        }
        c = geometry::read_obj_rig(file, rig, keep_sums);
      } else if (iqm) {
        cube2::IqmFile model = cube2::read_iqm_file(file, /*read_clips=*/false);
        if (!model.has_geometry()) throw geometry::GeometryError(relative + ": no geometry (an animation file)");
        if (model.model.joint_names.empty()) throw geometry::GeometryError(relative + ": no joints (a rigid prop)");
        if (!model.has_blend_weights) throw geometry::GeometryError(relative + ": no blend indexes/weights");
        model.model.name = relative;
        SourceRig source_rig = to_source_rig(model.model);
        c = std::move(source_rig.character);
        s.bind = std::move(source_rig.bind);
        s.up = Eigen::Vector3d::UnitZ();  // the Quake lineage's up axis (cube2.hpp)
      } else {
        geometry::ImportOptions import;
        import.weights = keep_sums;
        if (options_.animations) {
          import.clip_fps = options_.fps;
          import.max_clips = options_.max_animations_per_character;
        }
        geometry::ImportReport report;
        geometry::ImportedMotion motion;
        c = geometry::import_character(file, import, &report, &motion);
        if (report.source_up) rotate_to_y_up(c, motion, *report.source_up);
        if (!motion.no_bind.empty()) {
          spdlog::warn("{}: {}: no bind pose{}: {}", label, relative,
                       options_.animations ? " and no clips" : "", motion.no_bind);
        }
        s.bind = motion.bind;
        for (auto& clip : motion.clips) {
          s.animations.push_back({clip.name, clip.fps, std::move(clip.frames), motion.bind});
        }
        if (options_.animations) {
          spdlog::info("{}: {}: {} of {} clips kept{}{}", label, relative, s.animations.size(),
                       motion.num_file_clips,
                       motion.left_out.empty()
                           ? std::string()
                           : ", " + std::to_string(motion.left_out.size()) + " left out (" +
                                 std::to_string(motion.num_scaled_clips) + " scale a joint)",
                       motion.num_unread_clips > 0
                           ? ", " + std::to_string(motion.num_unread_clips) +
                                 " not read (max_animations_per_character)"
                           : std::string());
          for (const auto& why : motion.left_out) {
            spdlog::debug("{}: {}: clip {} left out", label, relative, why);
          }
        }
      }
      if (c.has_weights()) {
        const auto [off, worst] = renormalise(c.weights);
        if (off > 0) {
          spdlog::warn("{}: {}: the weights of {} of {} vertices did not sum to 1 (by up to {:.3g}); "
                       "renormalised", label, relative, off, c.mesh.num_vertices(), worst);
          ++renormalised_files;
          renormalised_vertices += off;
        }
      }
      std::string name = fs::path(relative).replace_extension().generic_string();
      std::replace(name.begin(), name.end(), '/', '.');
      name = options_.prefix + name;
      if (!names.insert(name).second) {
        throw IoError(relative + ": another file already gave a character named '" + name + "'");
      }
      c.name = name;
      s.character = std::move(c);
      s.source = label;
      s.path = relative;
      s.licence = options_.licence;
      s.attribution = options_.attribution;
      if (options_.skeleton.empty() || options_.skeleton == "stem") {
        s.skeleton = file.stem().string();
      } else if (options_.skeleton == "directory") {
        s.skeleton = file.parent_path().filename().string();
      } else {
        s.skeleton = options_.skeleton;
      }
      out.push_back(std::move(s));
    } catch (const std::exception& e) {
      excluded.push_back({label, relative, relative_message(e.what(), root_text)});
    }
  }
  for (std::size_t i = 0; i < options_.include.size(); ++i) {
    if (!include_used[i]) {
      throw ConfigError(options_.source.where + "dataset 'folder': include pattern '" +
                        options_.include[i] + "' matches no character file under " + root_text);
    }
  }
  for (std::size_t i = 0; i < options_.exclude.size(); ++i) {
    if (!exclude_used[i]) {
      throw ConfigError(options_.source.where + "dataset 'folder': exclude pattern '" +
                        options_.exclude[i].first + "' matches no character file under " +
                        root_text + " (a typo would keep what it means to exclude)");
    }
  }
  if (renormalised_files > 0) {
    spdlog::info("{}: renormalised the weights of {} vertices in {} files", label,
                 renormalised_vertices, renormalised_files);
  }
  return out;
}

}  // namespace skinlab::datasets

SKINLAB_REGISTER(dataset, folder, skinlab::datasets::Folder);

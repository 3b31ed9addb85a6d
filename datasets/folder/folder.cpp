#include "datasets/folder/folder.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <set>

#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/geometry/import_character.hpp"
#include "framework/geometry/rig_io.hpp"

namespace skinlab::datasets {

namespace fs = std::filesystem;

Folder::Options Folder::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "dataset 'folder'");
  f.required("path", o.path);
  f.optional("licence", o.licence);
  f.optional("attribution", o.attribution);
  f.optional("skeleton", o.skeleton);
  f.optional("recursive", o.recursive);
  f.check(!o.path.empty(), "path", "must not be empty");
  f.finish();
  return o;
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

/// Rotates V and joint positions so that `up` becomes +Y (the smallest rotation; 180° about X
/// for −Y), as NormalizeOptions::source_up would.
void rotate_to_y_up(geometry::Character& c, const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  if ((u - Eigen::Vector3d::UnitY()).norm() < 1e-12) return;
  const Eigen::Matrix3d R =
      (u + Eigen::Vector3d::UnitY()).norm() < 1e-12
          ? Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix()
          : Eigen::Quaterniond::FromTwoVectors(u, Eigen::Vector3d::UnitY()).toRotationMatrix();
  c.mesh.V = c.mesh.V * R.transpose();
  c.skeleton.positions = c.skeleton.positions * R.transpose();
}

}  // namespace

std::vector<SourceCharacter> Folder::read(std::vector<Excluded>& excluded) const {
  const fs::path root(options_.path);
  std::error_code ec;
  if (!fs::is_directory(root, ec)) {
    throw IoError(options_.path + ": dataset 'folder': not a readable directory");
  }
  std::vector<fs::path> files;
  try {
    if (options_.recursive) {
      for (const auto& e : fs::recursive_directory_iterator(root)) {
        if (e.is_regular_file()) files.push_back(e.path());
      }
    } else {
      for (const auto& e : fs::directory_iterator(root)) {
        if (e.is_regular_file()) files.push_back(e.path());
      }
    }
  } catch (const fs::filesystem_error& e) {
    throw IoError(options_.path + ": dataset 'folder': cannot list directory: " + e.what());
  }
  std::sort(files.begin(), files.end());

  std::vector<SourceCharacter> out;
  std::set<std::string> names;
  for (const auto& file : files) {
    const std::string ext = lower(file.extension().string());
    const bool obj = ext == ".obj";
    if (!obj && !is_assimp_character(ext)) continue;
    const std::string relative = fs::relative(file, root).generic_string();
    try {
      geometry::Character c;
      if (obj) {
        const fs::path rig = file.parent_path() / (file.stem().string() + "_rig.txt");
        if (!fs::exists(rig)) {
          throw IoError(relative + ": OBJ mesh without its RigNet rig file " +
                        rig.filename().string());
        }
        c = geometry::read_obj_rig(file, rig);
      } else {
        geometry::ImportReport report;
        c = geometry::import_character(file, {}, &report);
        if (report.source_up) rotate_to_y_up(c, *report.source_up);
      }
      std::string name = fs::path(relative).replace_extension().generic_string();
      std::replace(name.begin(), name.end(), '/', '.');
      if (!names.insert(name).second) {
        throw IoError(relative + ": another file already gave a character named '" + name + "'");
      }
      c.name = name;
      SourceCharacter s;
      s.character = std::move(c);
      s.source = "folder";
      s.path = relative;
      s.licence = options_.licence;
      s.attribution = options_.attribution;
      s.skeleton = options_.skeleton.empty() ? file.stem().string() : options_.skeleton;
      out.push_back(std::move(s));
    } catch (const std::exception& e) {
      excluded.push_back({"folder", relative, e.what()});
    }
  }
  return out;
}

}  // namespace skinlab::datasets

SKINLAB_REGISTER(dataset, folder, skinlab::datasets::Folder);

#include "framework/geometry/load_character.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <string>

#include "framework/geometry/import_character.hpp"

namespace skinlab::geometry {

namespace {

std::string lower_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace

std::vector<std::filesystem::path> rig_candidates(const std::filesystem::path& obj) {
  if (lower_extension(obj) != ".obj") return {};
  const std::string stem = obj.stem().string();
  const std::filesystem::path dir = obj.parent_path();
  std::vector<std::filesystem::path> candidates = {dir / (stem + "_rig.txt"), dir / (stem + ".txt")};
  const std::string remesh = "_remesh";
  if (stem.size() > remesh.size() && stem.compare(stem.size() - remesh.size(), remesh.size(), remesh) == 0) {
    candidates.push_back(dir / (stem.substr(0, stem.size() - remesh.size()) + "_ori_rig.txt"));
  }
  return candidates;
}

std::filesystem::path rig_beside(const std::filesystem::path& obj) {
  for (const auto& candidate : rig_candidates(obj)) {
    if (std::filesystem::is_regular_file(candidate)) return candidate;
  }
  return {};
}

bool is_character_file(const std::filesystem::path& file) {
  static const std::array<const char*, 10> kExtensions = {
      ".obj", ".fbx", ".glb", ".gltf", ".dae", ".b3d", ".iqm", ".smd", ".x", ".md5mesh"};
  const std::string ext = lower_extension(file);
  return std::find(kExtensions.begin(), kExtensions.end(), ext) != kExtensions.end();
}

Character load_character(const std::filesystem::path& file, const std::filesystem::path& rig,
                         SkinLines skin) {
  const std::string ext = lower_extension(file);
  if (!rig.empty()) {
    if (ext != ".obj") {
      throw GeometryError(file.string() + ": a rig file (" + rig.string() +
                          ") goes with an OBJ mesh; other formats carry their own skeleton");
    }
    return read_obj_rig(file, rig, {}, skin);
  }
  if (ext == ".obj") {
    const std::filesystem::path beside = rig_beside(file);
    if (beside.empty()) {
      std::string tried;
      for (const auto& candidate : rig_candidates(file)) {
        tried += (tried.empty() ? "" : ", ") + candidate.filename().string();
      }
      throw GeometryError(file.string() + ": an OBJ mesh has no skeleton; give its RigNet rig "
                          "file with --rig (none next to it: " + tried + ")");
    }
    return read_obj_rig(file, beside, {}, skin);
  }
  // glTF stores indexed vertices: keep them as they are, so that results map one to one onto
  // the file's own vertices. Other formats (B3D: one vertex per face corner) are joined.
  ImportOptions options;
  options.join_identical_vertices = ext != ".gltf" && ext != ".glb";
  return import_character(file, options);
}

}  // namespace skinlab::geometry

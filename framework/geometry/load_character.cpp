#include "framework/geometry/load_character.hpp"

#include <algorithm>
#include <cctype>

#include "framework/geometry/import_character.hpp"
#include "framework/geometry/rig_io.hpp"

namespace skinlab::geometry {

Character load_character(const std::filesystem::path& file, const std::filesystem::path& rig) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (!rig.empty()) {
    if (ext != ".obj") {
      throw GeometryError(file.string() + ": a rig file (" + rig.string() +
                          ") goes with an OBJ mesh; other formats carry their own skeleton");
    }
    return read_obj_rig(file, rig);
  }
  if (ext == ".obj") {
    throw GeometryError(file.string() + ": an OBJ mesh has no skeleton; give its RigNet rig file with --rig");
  }
  // glTF stores indexed vertices: keep them as they are, so that results map one to one onto
  // the file's own vertices. Other formats (B3D: one vertex per face corner) are joined.
  ImportOptions options;
  options.join_identical_vertices = ext != ".gltf" && ext != ".glb";
  return import_character(file, options);
}

}  // namespace skinlab::geometry

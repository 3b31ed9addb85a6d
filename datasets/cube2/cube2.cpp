#include "datasets/cube2/cube2.hpp"

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>

#include "datasets/cube2/iqm.hpp"
#include "datasets/debian_copyright.hpp"
#include "framework/core/registry.hpp"

namespace skinlab::datasets {

namespace fs = std::filesystem;

Cube2Builder::Options Cube2Builder::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "dataset 'cube2'");
  f.optional("path", o.path).check(!o.path.empty(), "path", "must not be empty");
  f.optional("copyright", o.copyright);
  f.optional("copyright_prefix", o.copyright_prefix);
  f.optional("exclude_dirs", o.exclude_dirs);
  f.finish();
  return o;
}

std::vector<SourceCharacter> Cube2Builder::read(std::vector<Excluded>& excluded) const {
  const fs::path root(options_.path);
  if (!fs::is_directory(root)) {
    throw IoError("dataset 'cube2': " + options_.path +
                  " is not a directory (install cube2-data or set 'path')");
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (entry.is_regular_file() && entry.path().extension() == ".iqm")
      files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());

  auto excluded_dir = [&](const fs::path& rel) -> std::optional<std::string> {
    for (const auto& part : rel.parent_path()) {
      if (std::find(options_.exclude_dirs.begin(), options_.exclude_dirs.end(), part.string()) !=
          options_.exclude_dirs.end()) {
        return part.string();
      }
    }
    return std::nullopt;
  };

  struct Parsed {
    fs::path rel;
    cube2::IqmFile iqm;
  };
  std::vector<Parsed> models;
  std::map<fs::path, std::vector<Parsed>> anims_by_dir;
  for (const auto& file : files) {
    const fs::path rel = file.lexically_relative(root);
    try {
      cube2::IqmFile iqm = cube2::read_iqm_file(file);
      if (iqm.has_geometry()) {
        models.push_back({rel, std::move(iqm)});
      } else if (!iqm.clips.empty()) {
        anims_by_dir[rel.parent_path()].push_back({rel, std::move(iqm)});
      } else {
        excluded.push_back({"cube2", rel.string(), "no geometry and no animation"});
      }
    } catch (const Error& e) {
      excluded.push_back({"cube2", rel.string(), e.what()});
    }
  }

  std::vector<SourceCharacter> out;
  std::map<std::string, bool> anim_used;
  for (auto& [rel, iqm] : models) {
    const std::string path = rel.string();
    if (auto dir = excluded_dir(rel)) {
      excluded.push_back({"cube2", path, "under '" + *dir + "/': not a character (exclude_dirs)"});
      continue;
    }
    if (iqm.model.joint_names.empty()) {
      excluded.push_back({"cube2", path, "no joints (a rigid prop)"});
      continue;
    }
    if (!iqm.has_blend_weights) {
      excluded.push_back({"cube2", path, "no blend indexes/weights"});
      continue;
    }
    SourceCharacter sc;
    sc.source = "cube2";
    sc.path = path;
    sc.skeleton = rel.has_parent_path() ? rel.begin()->string() : rel.stem().string();
    iqm.model.name = (rel.parent_path() / rel.stem()).generic_string();
    std::replace(iqm.model.name.begin(), iqm.model.name.end(), '/', '.');  // an HDF5 name
    sc.up = Eigen::Vector3d::UnitZ();
    SourceRig rig;
    try {
      rig = to_source_rig(iqm.model);
    } catch (const Error& e) {
      excluded.push_back({"cube2", path, e.what()});
      continue;
    }
    sc.bind = rig.bind;
    sc.character = std::move(rig.character);
    if (!options_.copyright.empty()) {
      const CopyrightInfo info =
          debian_copyright(options_.copyright, options_.copyright_prefix + path);
      sc.licence = info.licence;
      sc.attribution = info.attribution;
    }
    for (const auto& anim : anims_by_dir[rel.parent_path()]) {
      if (anim.iqm.pose_parents != iqm.model.parents) continue;
      anim_used[anim.rel.string()] = true;
      for (const auto& clip : anim.iqm.clips) {
        const auto frames = cube2::global_frames(clip, anim.iqm.pose_parents, iqm.model.joint_names,
                                                 anim.rel.string());
        sc.animations.push_back(make_animation(clip.name, clip.fps, frames, rig));
      }
    }
    out.push_back(std::move(sc));
  }
  for (const auto& [dir, anims] : anims_by_dir) {
    if (excluded_dir(dir / "x")) continue;  // animations of excluded models
    for (const auto& anim : anims) {
      if (!anim_used[anim.rel.string()]) {
        excluded.push_back(
            {"cube2", anim.rel.string(),
             "animation file whose pose hierarchy matches no model in its directory"});
      }
    }
  }
  return out;
}

}  // namespace skinlab::datasets

SKINLAB_REGISTER(dataset, cube2, skinlab::datasets::Cube2Builder);

#include "datasets/nexuiz/nexuiz.hpp"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <memory>
#include <regex>

#include "datasets/byte_reader.hpp"
#include "datasets/debian_copyright.hpp"
#include "datasets/nexuiz/pk3.hpp"
#include "datasets/nexuiz/zym.hpp"
#include "framework/core/registry.hpp"

namespace skinlab::datasets {

namespace fs = std::filesystem;

NexuizBuilder::Options NexuizBuilder::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "dataset 'nexuiz'");
  f.optional("path", o.path).check(!o.path.empty(), "path", "must not be empty");
  f.optional("copyright", o.copyright);
  f.optional("include", o.include);
  f.optional("lods", o.lods);
  f.finish();
  return o;
}

std::vector<SourceCharacter> NexuizBuilder::read(std::vector<Excluded>& excluded) const {
  // Members: name inside the tree and a loader of its bytes.
  std::vector<std::pair<std::string, std::function<std::string()>>> members;
  std::string where;  // prefix of error sources
  std::unique_ptr<nexuiz::ZipArchive> archive;
  if (fs::is_directory(options_.path)) {
    where = options_.path + "/";
    for (const auto& entry : fs::recursive_directory_iterator(options_.path)) {
      if (!entry.is_regular_file() || entry.path().extension() != ".zym") continue;
      const fs::path file = entry.path();
      members.emplace_back(file.lexically_relative(options_.path).generic_string(),
                           [file] { return read_binary_file(file); });
    }
  } else if (fs::is_regular_file(options_.path)) {
    where = options_.path + ":";
    archive = std::make_unique<nexuiz::ZipArchive>(options_.path);
    for (const auto& e : archive->entries()) {
      if (e.name.size() > 4 && e.name.compare(e.name.size() - 4, 4, ".zym") == 0) {
        const nexuiz::ZipArchive* a = archive.get();
        const nexuiz::ZipArchive::Entry* entry = &e;
        members.emplace_back(e.name, [a, entry] { return a->read(*entry); });
      }
    }
  } else {
    throw IoError("dataset 'nexuiz': " + options_.path +
                  " is neither a .pk3 archive nor a directory (install nexuiz-data or set 'path')");
  }
  std::sort(members.begin(), members.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });

  CopyrightInfo info;
  if (!options_.copyright.empty()) info = debian_copyright(options_.copyright, "");

  static const std::regex lod(R"((.*)_lod[0-9]+\.zym)");
  std::vector<SourceCharacter> out;
  for (const auto& [name, load] : members) {
    if (name.rfind(options_.include, 0) != 0) {
      excluded.push_back(
          {"nexuiz", name, "not under '" + options_.include + "': not a player character"});
      continue;
    }
    std::smatch match;
    if (!options_.lods && std::regex_match(name, match, lod)) {
      excluded.push_back({"nexuiz", name, "level-of-detail copy of " + match[1].str() + ".zym"});
      continue;
    }
    try {
      nexuiz::ZymFile zym = nexuiz::read_zym(load(), where + name);
      fs::path stem = fs::path(name);
      stem.replace_extension();
      std::string character = stem.generic_string();
      if (character.rfind("models/", 0) == 0) character = character.substr(7);
      std::replace(character.begin(), character.end(), '/', '.');  // an HDF5 name
      zym.model.name = character;
      SourceRig rig = to_source_rig(zym.model);
      SourceCharacter sc;
      sc.source = "nexuiz";
      sc.path = name;
      sc.licence = info.licence;
      sc.attribution = info.attribution;
      sc.skeleton = stem.filename().string();
      sc.up = Eigen::Vector3d::UnitZ();  // Quake units, Z up
      for (const auto& scene : zym.scenes) {
        const std::vector<Transforms> frames(
            zym.poses.begin() + scene.first_pose,
            zym.poses.begin() + scene.first_pose + scene.num_poses);
        sc.animations.push_back(make_animation(scene.name, scene.fps, frames, rig));
      }
      sc.bind = rig.bind;
      sc.character = std::move(rig.character);
      out.push_back(std::move(sc));
    } catch (const Error& e) {
      excluded.push_back({"nexuiz", name, e.what()});
    }
  }
  return out;
}

}  // namespace skinlab::datasets

SKINLAB_REGISTER(dataset, nexuiz, skinlab::datasets::NexuizBuilder);

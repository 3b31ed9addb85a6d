#include "datasets/openclonk/openclonk.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <memory>

#include "datasets/byte_reader.hpp"
#include "datasets/openclonk/c4group.hpp"
#include "framework/core/registry.hpp"

namespace skinlab::datasets {

namespace fs = std::filesystem;

namespace openclonk {
namespace {

/// The files a mesh builder needs: `.mesh` and `.skeleton` (case-insensitive).
bool is_ogre_file(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".mesh" || ext == ".skeleton";
}

}  // namespace
}  // namespace openclonk

OpenClonkBuilder::Options OpenClonkBuilder::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, "dataset 'openclonk'");
  f.optional("path", o.path).check(!o.path.empty(), "path", "must not be empty");
  o.read(f, "dataset 'openclonk'");
  f.finish();
  return o;
}

std::string OpenClonkBuilder::character_name(const std::string& path) {
  const fs::path p(path);
  std::string name = "openclonk";
  for (const auto& group : p.parent_path()) name += "." + group.stem().string();
  std::string graphics = p.stem().string();
  if (graphics.rfind("Graphics", 0) == 0) graphics = graphics.substr(8);
  if (!graphics.empty()) name += "." + graphics;
  return name;
}

std::vector<SourceCharacter> OpenClonkBuilder::read(std::vector<Excluded>& excluded) const {
  const fs::path root(options_.path);
  std::error_code ec;
  std::vector<fs::path> groups;  // packed group files, or unpacked groups (directories)
  if (fs::is_directory(root, ec)) {
    for (const auto& e : fs::directory_iterator(root, ec)) groups.push_back(e.path());
    if (ec) throw IoError(root.string() + ": dataset 'openclonk': cannot list: " + ec.message());
    std::sort(groups.begin(), groups.end());
  } else if (fs::is_regular_file(root, ec)) {
    groups.push_back(root);
  } else {
    throw IoError("dataset 'openclonk': " + root.string() +
                  " is neither OpenClonk's data directory nor a group file (install openclonk-data "
                  "or set 'path')");
  }

  ogre::Tree tree;
  tree.source = "openclonk";
  tree.where = root.string();
  tree.name = character_name;
  for (const fs::path& group : groups) {
    const std::string name = group.filename().string();
    if (fs::is_directory(group, ec)) {  // an unpacked group
      for (auto it = fs::recursive_directory_iterator(group, ec); !ec && it != fs::end(it);
           it.increment(ec)) {
        const fs::path file = it->path();
        const std::string path = name + "/" + file.lexically_relative(group).generic_string();
        if (it->is_regular_file() && openclonk::is_ogre_file(path)) {
          tree.files.push_back({path, [file] { return read_binary_file(file); }});
        }
      }
      if (ec) excluded.push_back({"openclonk", name, group.string() + ": cannot list: " + ec.message()});
      continue;
    }
    std::shared_ptr<const openclonk::C4Group> archive;
    try {
      archive = std::make_shared<const openclonk::C4Group>(openclonk::C4Group::open(group));
    } catch (const Error& e) {
      excluded.push_back({"openclonk", name, e.what()});
      continue;
    }
    std::size_t found = 0;
    for (const auto& entry : archive->entries()) {
      if (entry.group || !openclonk::is_ogre_file(entry.path)) continue;
      ++found;
      tree.files.push_back({name + "/" + entry.path, [archive, &entry] { return archive->read(entry); }});
    }
    spdlog::info("openclonk: {}: {} entries, {} of them .mesh or .skeleton files", name,
                 archive->entries().size(), found);
  }
  std::sort(tree.files.begin(), tree.files.end(),
            [](const ogre::TreeFile& a, const ogre::TreeFile& b) { return a.path < b.path; });
  return ogre::read_tree(tree, options_, excluded);
}

}  // namespace skinlab::datasets

SKINLAB_REGISTER(dataset, openclonk, skinlab::datasets::OpenClonkBuilder);

/// \file
/// `skinlab export <dataset.yaml> <character> --out FILE`: one character of a dataset's raw
/// sources (the builders of its `sources:`, e.g. 0 A.D.'s PMD files) as its artist made it, in
/// its own frame and vertex order, with its artist weights, as
///
///     .glb / .gltf   glTF 2.0 skin (geometry/gltf_export.hpp; at most 4 weights per vertex,
///                    as game engines keep them), rotated to glTF's +Y up if the source is not
///     .obj           OBJ mesh plus `<stem>_rig.txt` beside it (RigNet rig text, every weight)
///
/// So a game character of the dataset's test split can be fed to `skinlab predict`, Blender or
/// any other tool like a user's own file. Names are the dataset's (`skinlab dataset-card`).

#include <Eigen/Geometry>
#include <fmt/format.h>

#include <iostream>

#include "framework/cli/commands.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/prepare.hpp"
#include "framework/geometry/gltf_export.hpp"
#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/rig_io.hpp"

namespace skinlab::cli {

namespace {

namespace fs = std::filesystem;

int run_export(const std::string& config_file, const std::string& name, const fs::path& out) {
  const std::string ext = out.extension().string();
  if (ext != ".glb" && ext != ".gltf" && ext != ".obj") {
    throw Error(out.string() + ": unknown output type '" + ext + "' (use .glb, .gltf or .obj)");
  }
  const data::PrepareConfig config = data::PrepareConfig::from(config::Config::load(config_file));
  std::vector<datasets::Excluded> excluded;
  std::vector<std::string> names;
  for (const auto& node : config.sources) {
    for (auto& source : dataset_registry().create(node)->read(excluded)) {
      if (source.character.name != name) {
        names.push_back(source.character.name);
        continue;
      }
      geometry::Character c = std::move(source.character);
      if (ext == ".obj") {
        fs::path rig = out;
        rig.replace_filename(out.stem().string() + "_rig.txt");
        geometry::write_obj(out, c.mesh);
        geometry::write_rig(rig, c.skeleton, c.weights);
        std::cout << "wrote " << out.string() << " and " << rig.string() << "\n";
      } else {
        if (!source.up.isApprox(Eigen::Vector3d::UnitY())) {
          const Eigen::Matrix3d R =
              Eigen::Quaterniond::FromTwoVectors(source.up, Eigen::Vector3d::UnitY())
                  .toRotationMatrix();
          c.mesh.V = (c.mesh.V * R.transpose()).eval();
          c.skeleton.positions = (c.skeleton.positions * R.transpose()).eval();
        }
        geometry::write_gltf(out, c);
        std::cout << "wrote " << out.string() << "\n";
      }
      std::cout << fmt::format("{} ({}: {}): {} vertices, {} joints, licence {}, {}\n", name,
                               source.source, source.path, c.mesh.num_vertices(),
                               c.skeleton.num_joints(), source.licence, source.attribution);
      return 0;
    }
  }
  for (const auto& e : excluded) {
    if (fs::path(e.path).stem().string().rfind(name, 0) == 0) {
      throw Error(fmt::format("{}: character '{}' was excluded by its builder: {}", config_file,
                              name, e.reason));
    }
  }
  std::string known;
  for (std::size_t i = 0; i < names.size() && i < 12; ++i) known += (i ? ", " : "") + names[i];
  throw Error(fmt::format("{}: no character '{}' in its sources ({} characters: {}{})",
                          config_file, name, names.size(), known, names.size() > 12 ? ", ..." : ""));
}

}  // namespace

Command add_export(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "export", "one character of a dataset's raw sources with its artist weights (glTF or OBJ + rig)");
  auto config = std::make_shared<std::string>();
  auto name = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  cmd->add_option("dataset", *config, "dataset config, e.g. configs/datasets/games.yaml")
      ->required();
  cmd->add_option("character", *name, "character name (as in the dataset card)")->required();
  cmd->add_option("--out", *out, ".glb, .gltf, or .obj (with <stem>_rig.txt)")->required();
  return {cmd, [config, name, out] { return run_export(*config, *name, *out); }};
}

}  // namespace skinlab::cli

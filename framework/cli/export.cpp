/// \file
/// `skinlab export <dataset.yaml> <character>... (--out FILE | --out-dir DIR)`: characters of a
/// dataset's raw sources (the builders of its `sources:`, e.g. 0 A.D.'s PMD files) as their
/// artist made them, in their own vertex order and units, with their artist weights, as
///
///     .glb / .gltf   glTF 2.0 skin (geometry/gltf_export.hpp; at most 4 weights per vertex,
///                    as game engines keep them), rotated to glTF's +Y up if the source is not
///     .obj           OBJ mesh plus `<stem>_rig.txt` beside it (RigNet rig text, every weight)
///
/// Both formats are right-handed with faces wound counter-clockwise seen from outside (the glTF
/// 2.0 specification's front faces; OBJ by convention), so a left-handed source
/// (SourceCharacter::left_handed: 0 A.D. in its game frame) is mirrored front to back
/// (data/source.hpp make_right_handed: z → −z): its `_L` joints come out on its left, it faces +Z
/// as glTF assets do, and its faces point outwards. Written in the game's frame instead, every
/// 0 A.D. character was inside out for the programs that read front from back (Blender's bone
/// heat: its visibility test and normal-weighted distance) and a mirror image for the rest.
///
/// So a game character of the dataset's test split can be fed to `skinlab predict`, Blender or
/// any other tool like a user's own file. Names are the dataset's (`skinlab dataset-card`).
/// One character goes to `--out FILE`; any number to `--out-dir DIR` as DIR/<name>.<--format>.
/// The sources are read once for all of them (reading a large dataset's sources is most of the
/// time), and only until every named character has been found. Nothing is written unless every
/// name is found.

#include <Eigen/Geometry>
#include <fmt/format.h>

#include <iostream>
#include <map>
#include <set>

#include "framework/cli/commands.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/prepare.hpp"
#include "framework/data/source.hpp"
#include "framework/geometry/gltf_export.hpp"
#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/rig_io.hpp"

namespace skinlab::cli {

namespace {

namespace fs = std::filesystem;

void check_extension(const std::string& where, const std::string& ext) {
  if (ext != ".glb" && ext != ".gltf" && ext != ".obj") {
    throw Error(where + ": unknown output type '" + ext + "' (use .glb, .gltf or .obj)");
  }
}

/// Writes one character as `out` (its extension picks the format) and says so.
void write_character(datasets::SourceCharacter& source, const fs::path& out) {
  datasets::make_right_handed(source);
  geometry::Character& c = source.character;
  if (out.extension() == ".obj") {
    fs::path rig = out;
    rig.replace_filename(out.stem().string() + "_rig.txt");
    geometry::write_obj(out, c.mesh);
    geometry::write_rig(rig, c.skeleton, c.weights);
    std::cout << "wrote " << out.string() << " and " << rig.string() << "\n";
  } else {
    if (!source.up.isApprox(Eigen::Vector3d::UnitY())) {
      const Eigen::Matrix3d R =
          Eigen::Quaterniond::FromTwoVectors(source.up, Eigen::Vector3d::UnitY()).toRotationMatrix();
      c.mesh.V = (c.mesh.V * R.transpose()).eval();
      c.skeleton.positions = (c.skeleton.positions * R.transpose()).eval();
    }
    geometry::write_gltf(out, c);
    std::cout << "wrote " << out.string() << "\n";
  }
  std::cout << fmt::format("{} ({}: {}): {} vertices, {} joints, licence {}, {}\n", c.name,
                           source.source, source.path, c.mesh.num_vertices(),
                           c.skeleton.num_joints(), source.licence, source.attribution);
}

struct ExportArgs {
  std::string config;
  std::vector<std::string> names;
  std::string out;
  std::string out_dir;
  std::string format = "glb";
};

int run_export(const ExportArgs& a) {
  if (a.out.empty() == a.out_dir.empty()) {
    throw Error("export: give --out FILE (one character) or --out-dir DIR, not both or neither");
  }
  if (!a.out.empty() && a.names.size() != 1) {
    throw Error(fmt::format("export: --out names one file, but {} characters were given; use "
                            "--out-dir DIR", a.names.size()));
  }
  const std::string ext = a.out.empty() ? "." + a.format : fs::path(a.out).extension().string();
  check_extension(a.out.empty() ? "--format" : a.out, ext);
  std::set<std::string> wanted(a.names.begin(), a.names.end());

  const data::PrepareConfig config = data::PrepareConfig::from(config::Config::load(a.config));
  std::vector<datasets::Excluded> excluded;
  std::vector<std::string> others;
  std::map<std::string, datasets::SourceCharacter> found;
  for (const auto& node : config.sources) {
    if (found.size() == wanted.size()) break;
    for (auto& source : dataset_registry().create(node)->read(excluded)) {
      const std::string name = source.character.name;
      if (wanted.count(name)) {
        found.emplace(name, std::move(source));
      } else {
        others.push_back(name);
      }
    }
  }
  std::vector<std::string> problems;
  for (const auto& name : a.names) {
    if (found.count(name)) continue;
    std::string reason;
    for (const auto& e : excluded) {
      if (fs::path(e.path).stem().string().rfind(name, 0) == 0) {
        reason = fmt::format("character '{}' was excluded by its builder: {}", name, e.reason);
        break;
      }
    }
    problems.push_back(reason.empty() ? fmt::format("no character '{}' in its sources", name)
                                      : reason);
  }
  if (!problems.empty()) {
    std::string known, what;
    for (std::size_t i = 0; i < others.size() && i < 12; ++i) known += (i ? ", " : "") + others[i];
    for (const auto& p : problems) what += (what.empty() ? "" : "; ") + p;
    throw Error(fmt::format("{}: {} (nothing written; {} other characters read: {}{})", a.config,
                            what, others.size(), known,
                            others.size() > 12 ? ", ..." : ""));
  }
  if (!a.out_dir.empty()) fs::create_directories(a.out_dir);
  for (const auto& name : a.names) {
    auto it = found.find(name);
    if (it == found.end()) continue;  // a name given twice: written once
    write_character(it->second, a.out.empty() ? fs::path(a.out_dir) / (name + ext) : fs::path(a.out));
    found.erase(it);
  }
  return 0;
}

}  // namespace

Command add_export(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "export", "characters of a dataset's raw sources with their artist weights (glTF or OBJ + "
                "rig): one with --out FILE, or many with --out-dir DIR");
  auto args = std::make_shared<ExportArgs>();
  cmd->add_option("dataset", args->config, "dataset config, e.g. configs/datasets/games.yaml")
      ->required();
  cmd->add_option("characters", args->names, "character names (as in the dataset card)")
      ->required();
  cmd->add_option("--out", args->out, "one character: .glb, .gltf, or .obj (with <stem>_rig.txt)");
  cmd->add_option("--out-dir", args->out_dir, "many characters: write DIR/<name>.<format> each");
  cmd->add_option("--format", args->format, "with --out-dir: glb, gltf or obj (with <name>_rig.txt)")
      ->check(CLI::IsMember({"glb", "gltf", "obj"}))
      ->capture_default_str();
  return {cmd, [args] { return run_export(*args); }};
}

}  // namespace skinlab::cli

/// \file
/// `skinlab distance <character> [--rig rig.txt] --type <distance> [--option key=value ...]
///  [--out D.h5|D.csv]`: computes vertex–bone distances D (#V×#B, bones in Skeleton::bones()
/// order) for one character, prints a summary and optionally writes D.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <iostream>

#include "framework/cli/commands.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/h5.hpp"
#include "framework/distances/distance.hpp"
#include "framework/geometry/load_character.hpp"
#include "framework/geometry/normalize.hpp"

namespace skinlab::cli {

namespace {

struct DistanceArgs {
  std::string input;
  std::string rig;
  std::string type = "hollow_dist";
  std::vector<std::string> options;
  std::string out;
  bool raw = false;
};

std::string bone_label(const geometry::Skeleton& s, const geometry::Bone& b) {
  return b.helper ? s.names[b.start] + "(leaf)" : s.names[b.start] + "->" + s.names[b.end];
}

bool is_h5(const std::filesystem::path& out) {
  return out.extension() == ".h5" || out.extension() == ".hdf5";
}

/// Checked before any work, so a typo in --out does not cost a distance computation.
void check_output(const std::filesystem::path& out) {
  if (!out.empty() && !is_h5(out) && out.extension() != ".csv") {
    throw Error(out.string() + ": unknown output type '" + out.extension().string() +
                "' (use .h5 or .csv)");
  }
}

void write_distances(const std::filesystem::path& out, const geometry::Character& c,
                     const Eigen::MatrixXd& D, const std::string& type) {
  const auto bones = c.skeleton.bones();
  if (is_h5(out)) {
    data::RowMatrixXi pairs(bones.size(), 2);
    for (std::size_t b = 0; b < bones.size(); ++b) pairs.row(b) << bones[b].start, bones[b].end;
    data::H5Writer w(out);
    w.write("D", data::RowMatrixXd(D));
    w.write("bones", pairs);
    w.write("vertices", data::RowMatrixXd(c.mesh.V));
    w.write_attribute("distance", type);
    w.write_attribute("character", c.name);
    w.commit();
  } else {
    std::string text = "vertex";
    for (const auto& b : bones) text += "," + bone_label(c.skeleton, b);
    text += "\n";
    for (Eigen::Index v = 0; v < D.rows(); ++v) {
      text += std::to_string(v);
      for (Eigen::Index b = 0; b < D.cols(); ++b) text += fmt::format(",{}", D(v, b));
      text += "\n";
    }
    write_file_atomic(out, text);
  }
}

int run(const DistanceArgs& args) {
  check_output(args.out);
  geometry::Character c = geometry::load_character(args.input, args.rig);
  if (!args.raw) geometry::normalize(c);
  config::Config options = config::Config::parse("type: " + args.type, "--type");
  for (const auto& o : args.options) options.apply_override(o);
  const auto distance = distance_registry().create(options.root());

  const auto start = std::chrono::steady_clock::now();
  const Eigen::MatrixXd D = distance->compute(c.mesh, c.skeleton);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::cout << fmt::format("{}: {} vertices, {} joints, {} bones ({} frame)\n", c.name,
                           c.mesh.num_vertices(), c.skeleton.num_joints(), D.cols(),
                           args.raw ? "file's" : "normalised 1 m");
  std::cout << fmt::format("{}: {:.3f} s; D min {:.4f} mean {:.4f} max {:.4f}\n", args.type,
                           seconds, D.minCoeff(), D.mean(), D.maxCoeff());
  if (!args.out.empty()) {
    write_distances(args.out, c, D, args.type);
    std::cout << "wrote " << args.out << "\n";
  }
  return 0;
}

}  // namespace

Command add_distance(CLI::App& app) {
  auto* cmd = app.add_subcommand("distance", "vertex-bone distances of one character");
  auto args = std::make_shared<DistanceArgs>();
  cmd->add_option("input", args->input, "character file (FBX, glTF, DAE, B3D, ... or OBJ with --rig)")
      ->required();
  cmd->add_option("--rig", args->rig, "RigNet rig text file for an OBJ mesh");
  cmd->add_option("--type", args->type, "distance registry key")->capture_default_str();
  cmd->add_option("--option", args->options, "distance option key=value (repeatable)");
  cmd->add_option("--out", args->out, "write D to a .h5 or .csv file");
  cmd->add_flag("--raw", args->raw, "keep the file's frame instead of normalising to 1 m height");
  return {cmd, [args] { return run(*args); }};
}

}  // namespace skinlab::cli

/// \file
/// `skinlab dataset-info <file.h5>`: reads and validates a dataset file (datasets/FORMAT.md) and
/// prints its counts, every character's sizes and distances, the splits and the exclusions.

#include <fmt/format.h>

#include <algorithm>
#include <iostream>

#include "framework/cli/commands.hpp"
#include "framework/data/dataset_file.hpp"

namespace skinlab::cli {

namespace {

/// Vertices after merging: the vertex map's image is 0..n−1 (subdivision appends after them).
int merged(const data::PreparedCharacter& c) {
  return c.vertex_map.empty() ? 0 : *std::max_element(c.vertex_map.begin(), c.vertex_map.end()) + 1;
}

int run_dataset_info(const std::string& file) {
  const data::Dataset d = data::read_dataset(file);
  std::cout << fmt::format("{}: format_version {}, skinlab {}\n", file, data::kFormatVersion,
                           d.git_commit);
  std::cout << fmt::format("characters: {}\n", d.characters.size());
  for (const auto& c : d.characters) {
    std::string distances;
    for (const auto& [type, dd] : c.distances) {
      distances +=
          (distances.empty() ? "" : ", ") + type + fmt::format(" (K={})", dd.topk_index.cols());
    }
    std::cout << fmt::format(
        "  {}: {} vertices ({} original, {} merged, {} subdivision levels), {} faces, {} joints, "
        "{} bones, "
        "{} animations; distances: {}; source {} ({}), skeleton {}, group {}, licence {}\n",
        c.name, c.num_vertices(), c.vertex_map.size(), merged(c), c.subdivision_levels, c.F.rows(),
        c.num_joints(), c.num_bones(), c.animations.size(), distances.empty() ? "none" : distances,
        c.source, c.path, c.skeleton, c.group, c.licence.empty() ? "unknown" : c.licence);
  }
  std::cout << fmt::format("splits: {}\n", d.splits.size());
  for (const auto& [name, s] : d.splits) {
    std::cout << fmt::format("  {}: train {}, val {}, test {}\n", name, s.train.size(),
                             s.val.size(), s.test.size());
  }
  std::cout << fmt::format("excluded: {}\n", d.excluded.size());
  for (const auto& e : d.excluded) {
    std::cout << fmt::format("  {}:{}: {}\n", e.source, e.path, e.reason);
  }
  return 0;
}

}  // namespace

Command add_dataset_info(CLI::App& app) {
  auto* cmd = app.add_subcommand("dataset-info",
                                 "counts, characters, distances and splits of a "
                                 "dataset file");
  auto file = std::make_shared<std::string>();
  cmd->add_option("file", *file, "dataset file (.h5)")->required();
  return {cmd, [file] { return run_dataset_info(*file); }};
}

}  // namespace skinlab::cli

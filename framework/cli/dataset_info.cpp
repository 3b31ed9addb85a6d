/// \file
/// `skinlab dataset-info <file.h5>`: reads and validates a dataset file (datasets/FORMAT.md) and
/// prints its counts, every character's sizes and distances, the splits and the exclusions, and
/// how much of the artist weights the K candidate bones of each distance can express.
///
/// Candidate coverage, per distance type, over all characters and over each split's test part
/// (entries are vertex×bone pairs with artist weight above 1e-4, the influence threshold of
/// HeterSkinNet Sec. 4.2 and of the `precision_recall` metric):
/// - influences per vertex: how many bones influence a vertex (the histogram 1, 2, 3, 4, 5+);
/// - entry coverage: the share of influential entries whose bone is one of the vertex's K
///   candidates, i.e. the highest recall any method that predicts over the candidates can reach
///   (before pruning); pooled over all entries of the characters;
/// - weight coverage: the mean over vertices of the artist weight on the candidates (what the
///   training targets keep before renormalisation).

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <iostream>
#include <map>
#include <numeric>

#include "framework/cli/commands.hpp"
#include "framework/data/dataset_file.hpp"

namespace skinlab::cli {

namespace {

/// Vertices after merging: the vertex map's image is 0..n−1 (subdivision appends after them).
int merged(const data::PreparedCharacter& c) {
  return c.vertex_map.empty() ? 0 : *std::max_element(c.vertex_map.begin(), c.vertex_map.end()) + 1;
}

/// Influence threshold of the coverage figures (precision_recall's default, Sec. 4.2).
constexpr double kInfluential = 1e-4;

/// Prints the candidate coverage of `distance` over the characters `which` of `d`.
void print_coverage(const data::Dataset& d, const std::vector<int>& which,
                    const std::string& label) {
  std::map<std::string, std::array<double, 3>> per_distance;  // covered, weight sum, vertices
  std::array<long, 6> histogram{};                            // 0 .. 5+ influences
  long entries = 0;
  for (int i : which) {
    const data::PreparedCharacter& c = d.characters[i];
    for (int v = 0; v < c.weights.rows(); ++v) {
      int n = 0;
      for (geometry::SparseWeights::InnerIterator it(c.weights, v); it; ++it) {
        n += it.value() > kInfluential;
      }
      ++histogram[std::min(n, 5)];
      entries += n;
    }
    for (const auto& [type, dd] : c.distances) {
      auto& acc = per_distance[type];
      acc[0] += static_cast<double>((dd.targets.array() > kInfluential).count());
      acc[1] += dd.targets.sum();
      acc[2] += static_cast<double>(dd.targets.rows());
    }
  }
  long vertices = 0;
  for (long h : histogram) vertices += h;
  if (vertices == 0) return;
  std::cout << fmt::format("candidate coverage, {} ({} characters, {} vertices):\n", label,
                           which.size(), vertices);
  std::cout << fmt::format(
      "  influences per vertex (weight > {}): 1: {:.1f}%, 2: {:.1f}%, 3: {:.1f}%, 4: {:.1f}%, "
      "5+: {:.1f}%, none: {:.1f}%\n",
      kInfluential, 100.0 * histogram[1] / vertices, 100.0 * histogram[2] / vertices,
      100.0 * histogram[3] / vertices, 100.0 * histogram[4] / vertices,
      100.0 * histogram[5] / vertices, 100.0 * histogram[0] / vertices);
  for (const auto& [type, acc] : per_distance) {
    std::cout << fmt::format(
        "  {}: entry coverage {:.2f}% (the recall ceiling of K-candidate methods), weight "
        "coverage {:.2f}%\n",
        type, entries > 0 ? 100.0 * acc[0] / entries : 0.0,
        acc[2] > 0 ? 100.0 * acc[1] / acc[2] : 0.0);
  }
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
  std::vector<int> all(d.characters.size());
  std::iota(all.begin(), all.end(), 0);
  print_coverage(d, all, "all characters");
  for (const auto& [name, s] : d.splits)
    print_coverage(d, s.test, "test part of split '" + name + "'");
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

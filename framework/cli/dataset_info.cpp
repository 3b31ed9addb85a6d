/// \file
/// `skinlab dataset-info <file.h5>`: reads and validates a dataset file (datasets/FORMAT.md) and
/// prints its counts, every character's sizes and distances, the splits and the exclusions, and
/// how much of the artist weights the K candidate bones of each distance can express.
///
/// Candidate coverage, per distance type, over all characters and over each split's test part
/// (entries are vertex×bone pairs with artist weight above 1e-4, the influence threshold of
/// HeterSkinNet Sec. 4.2 and of the `precision_recall` metric):
/// - influences per vertex: how many bones influence a vertex (the histogram 1, 2, 3, 4, 5+);
/// - entry and weight coverage for K = 1..6 (data/coverage.hpp, the paper's Fig. 6): the share
///   of influential entries, and of the artist weight, on each vertex's K nearest bones; entry
///   coverage at the prepared K is the highest recall any method that predicts over the
///   candidates can reach (before pruning);
/// - what the missed entries at the prepared K are: helper bones, distance ties, and candidate
///   slots taken by bones of joints that carry no weight.
/// `--coverage-figures DIR` draws the coverage curves per distance and writes them as CSV.

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <iostream>
#include <map>

#include "framework/cli/commands.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/data/coverage.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/report/plot.hpp"

namespace skinlab::cli {

namespace {

/// Vertices after merging: the vertex map's image is 0..n−1 (subdivision appends after them).
int merged(const data::PreparedCharacter& c) {
  return c.vertex_map.empty() ? 0 : *std::max_element(c.vertex_map.begin(), c.vertex_map.end()) + 1;
}

/// K = 1..kMaxK in the coverage table and figure (the paper's Fig. 6 runs to 6 or so).
constexpr int kMaxK = 6;

/// Coverage of every stored distance over the characters `which` of `d` (those with weights).
std::map<std::string, data::Coverage> coverage_of(const data::Dataset& d,
                                                  const std::vector<int>& which) {
  std::map<std::string, data::Coverage> out;
  for (int i : which) {
    const data::PreparedCharacter& c = d.characters[i];
    if (c.weights.rows() == 0) continue;
    for (const auto& [type, dd] : c.distances) {
      const int k = std::max(1, std::min<int>(static_cast<int>(dd.topk_index.cols()), kMaxK));
      out[type].add(data::candidate_coverage(c, type, kMaxK, k));
    }
  }
  return out;
}

/// Prints the candidate coverage `coverage` (data/coverage.hpp, per distance) of the
/// characters `which` of `d`.
void print_coverage(const data::Dataset& d, const std::vector<int>& which,
                    const std::map<std::string, data::Coverage>& coverage,
                    const std::string& label) {
  std::array<long, 6> histogram{};  // 0 .. 5+ influences per vertex
  for (int i : which) {
    const data::PreparedCharacter& c = d.characters[i];
    for (int v = 0; v < c.weights.rows(); ++v) {
      int n = 0;
      for (geometry::SparseWeights::InnerIterator it(c.weights, v); it; ++it) {
        n += it.value() > data::kInfluential;
      }
      ++histogram[std::min(n, 5)];
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
      data::kInfluential, 100.0 * histogram[1] / vertices, 100.0 * histogram[2] / vertices,
      100.0 * histogram[3] / vertices, 100.0 * histogram[4] / vertices,
      100.0 * histogram[5] / vertices, 100.0 * histogram[0] / vertices);
  for (const auto& [type, cov] : coverage) {
    std::string entry, weight;
    for (int k = 1; k <= cov.max_k; ++k) {
      entry += fmt::format(" {}: {:.2f}%", k, 100 * cov.entry_share(k));
      weight += fmt::format(" {}: {:.2f}%", k, 100 * cov.weight_share(k));
    }
    std::cout << fmt::format("  {}: entry coverage at K ={} (at the prepared K = {}: the recall "
                             "ceiling of K-candidate methods)\n",
                             type, entry, cov.diagnose_k);
    std::cout << fmt::format("  {}: weight coverage at K ={}\n", type, weight);
    std::cout << fmt::format(
        "  {}: missed at K = {}: {} influential entries, {:.1f}% of them on a leaf's helper "
        "bone, {:.1f}% tied in distance with the K-th candidate; {:.1f}% of the candidate slots "
        "hold a bone whose joint has no weight anywhere on its character\n",
        type, cov.diagnose_k, cov.missed,
        cov.missed > 0 ? 100.0 * cov.missed_helper / cov.missed : 0.0,
        cov.missed > 0 ? 100.0 * cov.missed_tied / cov.missed : 0.0,
        cov.slots > 0 ? 100.0 * cov.weightless_slots / cov.slots : 0.0);
  }
}

/// Coverage per part ("all", then "test:<split>") and distance.
using PartCoverage = std::vector<std::pair<std::string, std::map<std::string, data::Coverage>>>;

/// Fig. 6 on the dataset: per distance, weight coverage (blue) and entry coverage (orange)
/// against K over all characters, as `coverage_<distance>.png`, and every value of `parts` in
/// `coverage.csv` (distance, part, K, entry, weight), in `dir`.
void write_coverage_figures(const PartCoverage& parts, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  std::string csv = "distance,part,k,entry_coverage,weight_coverage\n";
  for (const auto& [part, coverage] : parts) {
    for (const auto& [type, cov] : coverage) {
      for (int k = 1; k <= cov.max_k; ++k) {
        csv += fmt::format("{},{},{},{:.6f},{:.6f}\n", type, part, k, cov.entry_share(k),
                           cov.weight_share(k));
      }
      if (part != "all") continue;
      report::Series weight, entry;
      weight.colour = {70, 110, 170};
      entry.colour = {230, 130, 40};
      for (int k = 1; k <= cov.max_k; ++k) {
        weight.x.push_back(k);
        weight.y.push_back(cov.weight_share(k));
        entry.x.push_back(k);
        entry.y.push_back(cov.entry_share(k));
      }
      report::write_png(dir / ("coverage_" + type + ".png"), report::line_plot({weight, entry}));
    }
  }
  write_file_atomic(dir / "coverage.csv", csv);
  std::cout << fmt::format("coverage figures and coverage.csv written to {}\n", dir.string());
}

int run_dataset_info(const std::string& file, const std::string& figures) {
  const data::Dataset d = data::read_dataset(file);
  std::cout << fmt::format("{}: format_version {}, skinlab {}\n", file, data::kFormatVersion,
                           d.git_commit);
  std::vector<int> originals;  // every character but the augmented copies (data/augment.hpp)
  for (std::size_t i = 0; i < d.characters.size(); ++i) {
    if (!d.characters[i].is_augmented_copy()) originals.push_back(static_cast<int>(i));
  }
  const std::size_t copies = d.characters.size() - originals.size();
  std::cout << fmt::format(
      "characters: {}{}\n", d.characters.size(),
      copies > 0 ? fmt::format(" ({} of them augmented training copies)", copies) : std::string());
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
    if (c.is_augmented_copy()) {
      std::cout << fmt::format("    augmented copy of {}\n", c.augmented_from);
    }
  }
  std::cout << fmt::format("splits: {}\n", d.splits.size());
  for (const auto& [name, s] : d.splits) {
    std::cout << fmt::format("  {}: train {}, val {}, test {}\n", name, s.train.size(),
                             s.val.size(), s.test.size());
  }
  PartCoverage parts{{"all", coverage_of(d, originals)}};
  print_coverage(d, originals, parts.back().second,
                 copies > 0 ? "all characters (augmented copies left out)" : "all characters");
  for (const auto& [name, s] : d.splits) {
    parts.emplace_back("test:" + name, coverage_of(d, s.test));
    print_coverage(d, s.test, parts.back().second, "test part of split '" + name + "'");
  }
  if (!figures.empty()) write_coverage_figures(parts, figures);
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
  auto figures = std::make_shared<std::string>();
  cmd->add_option("file", *file, "dataset file (.h5)")->required();
  cmd->add_option("--coverage-figures", *figures,
                  "directory for the candidate-coverage figures (HeterSkinNet Fig. 6 per "
                  "distance) and coverage.csv");
  return {cmd, [file, figures] { return run_dataset_info(*file, *figures); }};
}

}  // namespace skinlab::cli

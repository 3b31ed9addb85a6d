#include "framework/data/clean.hpp"

#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

#include "framework/core/error.hpp"
#include "framework/geometry/normalize.hpp"

namespace skinlab::data {

CleaningOptions CleaningOptions::from(const config::Node& node) {
  CleaningOptions o;
  config::Fields f(node, "cleaning", {});
  f.optional("min_bones", o.min_bones);
  f.optional("drop_rigid", o.drop_rigid);
  f.optional("quantum", o.quantum);
  f.optional("group_cell", o.group_cell);
  f.optional("group_similarity", o.group_similarity);
  const config::Node exclude = f.section("exclude");
  if (exclude.exists() && !exclude.is_null()) {
    if (!exclude.is_map()) exclude.fail("expected a map of character name → reason");
    for (const auto& name : exclude.keys()) o.exclude[name] = exclude[name].as<std::string>();
  }
  f.optional("skeletons", o.skeletons);
  f.check(o.min_bones >= 0, "min_bones", "must be ≥ 0");
  f.check(o.quantum > 0, "quantum", "must be positive");
  f.check(o.group_cell > 0, "group_cell", "must be positive");
  f.check(o.group_similarity >= 0, "group_similarity", "must be ≥ 0 (above 1 turns grouping off)");
  f.finish();
  return o;
}

namespace {

constexpr std::uint64_t kFnvOffset = 1469598103934665603ull;
constexpr std::uint64_t kFnvPrime = 1099511628211ull;

void fnv(std::uint64_t& h, std::int64_t value) {
  for (int byte = 0; byte < 8; ++byte) {
    h ^= static_cast<std::uint64_t>(value >> (8 * byte)) & 0xffu;
    h *= kFnvPrime;
  }
}

geometry::Character normalised(const geometry::Character& c) {
  geometry::Character copy;
  copy.name = c.name;
  copy.mesh = c.mesh;
  copy.skeleton = c.skeleton;
  geometry::normalize(copy);
  return copy;
}

/// Joints with a positive weight, and whether every vertex has exactly one joint.
struct WeightUse {
  int joints = 0;
  bool rigid = true;
};

WeightUse weight_use(const geometry::SparseWeights& W) {
  WeightUse use;
  std::vector<char> used(static_cast<std::size_t>(W.cols()), 0);
  for (int v = 0; v < W.outerSize(); ++v) {
    int positive = 0;
    double largest = 0;
    for (geometry::SparseWeights::InnerIterator it(W, v); it; ++it) {
      if (it.value() <= 0) continue;
      ++positive;
      largest = std::max(largest, it.value());
      used[static_cast<std::size_t>(it.col())] = 1;
    }
    if (positive != 1 && largest < 1 - 1e-6) use.rigid = false;
  }
  use.joints = static_cast<int>(std::count(used.begin(), used.end(), 1));
  return use;
}

/// Occupied cells (packed 3×21-bit keys) of the surface of an already normalised mesh.
std::vector<std::uint64_t> occupied_cells(const geometry::Mesh& mesh, double cell) {
  std::unordered_set<std::uint64_t> cells;
  auto add = [&](const Eigen::Vector3d& p) {
    std::uint64_t key = 0;
    for (int a = 0; a < 3; ++a) {
      const auto i = static_cast<std::int64_t>(std::floor(p[a] / cell)) + (1 << 20);
      key =
          (key << 21) | (static_cast<std::uint64_t>(std::clamp<std::int64_t>(i, 0, (1 << 21) - 1)));
    }
    cells.insert(key);
  };
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose();
    const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1)).transpose();
    const Eigen::Vector3d c = mesh.V.row(mesh.F(f, 2)).transpose();
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(longest / (0.5 * cell))));
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        const double u = static_cast<double>(i) / n, v = static_cast<double>(j) / n;
        add(a + u * (b - a) + v * (c - a));
      }
    }
  }
  std::vector<std::uint64_t> out(cells.begin(), cells.end());
  std::sort(out.begin(), out.end());
  return out;
}

/// Share of the occupied cells of either surface that have an occupied cell of the other within
/// one cell (26-neighbourhood): (|A near B| + |B near A|) / (|A| + |B|). The one-cell tolerance
/// makes it insensitive to how the grid happens to cut a surface (a flat sheet on a cell face).
double overlap(const std::vector<std::uint64_t>& a, const std::vector<std::uint64_t>& b) {
  if (a.empty() && b.empty()) return 1.0;
  auto near = [](const std::vector<std::uint64_t>& from, const std::vector<std::uint64_t>& to) {
    std::size_t count = 0;
    for (std::uint64_t key : from) {
      bool found = false;
      for (int dz = -1; dz <= 1 && !found; ++dz) {
        for (int dy = -1; dy <= 1 && !found; ++dy) {
          for (int dx = -1; dx <= 1 && !found; ++dx) {
            // Packed x|y|z with 21 bits each and coordinates offset by 2^20: adding a signed
            // offset per field cannot carry across fields for cells inside the range. Shifted
            // as unsigned (modulo 2^64, the same bits): shifting a negative signed value left is
            // undefined before C++20 (UBSan found -1 << 42 here).
            const std::uint64_t k = key + (static_cast<std::uint64_t>(dx) << 42) +
                                    (static_cast<std::uint64_t>(dy) << 21) +
                                    static_cast<std::uint64_t>(dz);
            found = std::binary_search(to.begin(), to.end(), k);
          }
        }
      }
      count += found ? 1 : 0;
    }
    return count;
  };
  return static_cast<double>(near(a, b) + near(b, a)) / static_cast<double>(a.size() + b.size());
}

std::string skeleton_key(const datasets::SourceCharacter& c) {
  std::string key = c.skeleton;
  for (const auto& name : c.character.skeleton.names) key += '\n' + name;
  return key;
}

int find(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

}  // namespace

std::uint64_t geometry_hash(const geometry::Character& character, double quantum) {
  const geometry::Character c = normalised(character);
  // Each triangle as its three quantised corners, rotated so the smallest corner comes first
  // (keeps orientation), and the triangles sorted: the hash ignores vertex order, face order
  // and vertices split at UV seams, which differ between copies of one mesh.
  using Corner = std::array<std::int64_t, 3>;
  std::vector<std::array<Corner, 3>> triangles(static_cast<std::size_t>(c.mesh.num_faces()));
  for (int f = 0; f < c.mesh.num_faces(); ++f) {
    auto& t = triangles[static_cast<std::size_t>(f)];
    for (int k = 0; k < 3; ++k) {
      for (int a = 0; a < 3; ++a) {
        t[static_cast<std::size_t>(k)][static_cast<std::size_t>(a)] =
            std::llround(c.mesh.V(c.mesh.F(f, k), a) / quantum);
      }
    }
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  }
  std::sort(triangles.begin(), triangles.end());
  std::uint64_t h = kFnvOffset;
  fnv(h, static_cast<std::int64_t>(triangles.size()));
  for (const auto& t : triangles) {
    for (const auto& corner : t) {
      for (std::int64_t x : corner) fnv(h, x);
    }
  }
  return h;
}

double surface_similarity(const geometry::Character& a, const geometry::Character& b, double cell) {
  return overlap(occupied_cells(normalised(a).mesh, cell),
                 occupied_cells(normalised(b).mesh, cell));
}

std::vector<CleanedCharacter> clean(std::vector<datasets::SourceCharacter> characters,
                                    const CleaningOptions& options,
                                    std::vector<datasets::Excluded>& excluded) {
  for (const auto& [name, reason] : options.exclude) {
    if (std::none_of(characters.begin(), characters.end(), [&](const datasets::SourceCharacter& c) {
          return c.character.name == name;
        })) {
      throw Error("cleaning.exclude: no source gives a character named '" + name + "'");
    }
  }
  std::vector<datasets::SourceCharacter> kept;
  std::unordered_map<std::uint64_t, std::string> seen;  // geometry hash → first name
  for (auto& c : characters) {
    auto drop = [&](const std::string& reason) {
      spdlog::info("cleaning: dropped {} ({})", c.character.name, reason);
      excluded.push_back({c.source, c.path, c.character.name + ": " + reason});
    };
    if (auto it = options.exclude.find(c.character.name); it != options.exclude.end()) {
      drop("excluded by the config: " + it->second);
      continue;
    }
    if (!options.skeletons.empty() &&
        std::find(options.skeletons.begin(), options.skeletons.end(), c.skeleton) ==
            options.skeletons.end()) {
      drop("skeleton family '" + c.skeleton + "' is not in cleaning.skeletons");
      continue;
    }
    if (!c.character.has_weights()) {
      drop("no skin weights (nothing to learn)");
      continue;
    }
    const WeightUse use = weight_use(c.character.weights);
    if (use.joints < options.min_bones) {
      drop("weights use " + std::to_string(use.joints) +
           " joint(s), fewer than min_bones = " + std::to_string(options.min_bones));
      continue;
    }
    if (options.drop_rigid && use.rigid) {
      drop("rigid-only weights: every vertex is bound to a single joint");
      continue;
    }
    const std::uint64_t hash = geometry_hash(c.character, options.quantum);
    auto [it, inserted] = seen.try_emplace(hash, c.character.name);
    if (!inserted) {
      drop("duplicate geometry of " + it->second);
      continue;
    }
    kept.push_back(std::move(c));
  }

  const int n = static_cast<int>(kept.size());
  std::vector<int> parent(static_cast<std::size_t>(n));
  std::iota(parent.begin(), parent.end(), 0);
  if (options.group_similarity <= 1) {
    std::map<std::string, std::vector<int>> by_skeleton;
    for (int i = 0; i < n; ++i)
      by_skeleton[skeleton_key(kept[static_cast<std::size_t>(i)])].push_back(i);
    // Occupied cells of every character, and the overlap of every same-skeleton pair, in
    // parallel (TBB, in the caller's arena); the union below is serial and in pair order, so
    // the groups do not depend on the thread count.
    std::vector<std::vector<std::uint64_t>> cells(static_cast<std::size_t>(n));
    tbb::parallel_for(0, n, [&](int i) {
      cells[static_cast<std::size_t>(i)] = occupied_cells(
          normalised(kept[static_cast<std::size_t>(i)].character).mesh, options.group_cell);
    });
    std::vector<std::pair<int, int>> pairs;
    for (const auto& [key, members] : by_skeleton) {
      for (std::size_t x = 0; x < members.size(); ++x) {
        for (std::size_t y = x + 1; y < members.size(); ++y)
          pairs.emplace_back(members[x], members[y]);
      }
    }
    std::vector<double> similarity(pairs.size());
    tbb::parallel_for(std::size_t{0}, pairs.size(), [&](std::size_t k) {
      similarity[k] = overlap(cells[static_cast<std::size_t>(pairs[k].first)],
                              cells[static_cast<std::size_t>(pairs[k].second)]);
    });
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      if (similarity[k] < options.group_similarity) continue;
      const auto [a, b] = pairs[k];
      spdlog::debug("cleaning: {} ~ {} (similarity {:.4f})",
                    kept[static_cast<std::size_t>(a)].character.name,
                    kept[static_cast<std::size_t>(b)].character.name, similarity[k]);
      const int ra = find(parent, a), rb = find(parent, b);
      parent[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
    }
  }
  std::vector<std::string> group(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    group[static_cast<std::size_t>(i)] =
        kept[static_cast<std::size_t>(find(parent, i))].character.name;
  std::vector<CleanedCharacter> out;
  for (int i = 0; i < n; ++i) {
    CleanedCharacter c;
    c.group = group[static_cast<std::size_t>(i)];
    c.source = std::move(kept[static_cast<std::size_t>(i)]);
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace skinlab::data

#include "framework/data/splits.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "framework/core/error.hpp"
#include "framework/core/text.hpp"

namespace skinlab::data {

SplitOptions SplitOptions::from(const config::Node& node) {
  SplitOptions o;
  config::Fields f(node, "splits", {});
  std::int64_t seed = 0;
  f.optional("seed", seed);
  f.check(seed >= 0, "seed", "must be ≥ 0");
  o.seed = static_cast<std::uint64_t>(seed);
  std::vector<double> fractions(o.fractions.begin(), o.fractions.end());
  f.optional("fractions", fractions);
  f.check(fractions.size() == 3, "fractions", "must be a list of 3 numbers: [train, val, test]");
  double sum = 0;
  for (double x : fractions) {
    f.check(x >= 0 && std::isfinite(x), "fractions", "must be finite and ≥ 0");
    sum += x;
  }
  f.check(std::abs(sum - 1) < 1e-6, "fractions", "must sum to 1");
  std::copy(fractions.begin(), fractions.end(), o.fractions.begin());
  f.optional("heldout_skeletons", o.heldout_skeletons);
  const config::Node leave = f.section("leave_out_sources");
  if (leave.exists() && !leave.is_null()) {
    if (!leave.is_map()) leave.fail("expected a map: split name → list of sources");
    for (const auto& name : leave.keys()) {
      auto sources = leave[name].as<std::vector<std::string>>();
      if (sources.empty()) leave[name].fail("needs at least one source");
      if (name.empty() || name.find('/') != std::string::npos) {
        leave[name].fail("a split name must be non-empty and have no '/'");
      }
      o.leave_out_sources.emplace(name, std::move(sources));
    }
  }
  f.finish();
  return o;
}

namespace {

/// Uniform integer in [0, n) from the raw engine output (rejection sampling), independent of
/// the standard library's distribution implementation.
std::uint64_t draw(std::mt19937_64& rng, std::uint64_t n) {
  const std::uint64_t limit =
      std::numeric_limits<std::uint64_t>::max() - std::numeric_limits<std::uint64_t>::max() % n;
  std::uint64_t x;
  do {
    x = rng();
  } while (x >= limit);
  return x % n;
}

/// Assigns the characters `members` (indices) to train/val/test by whole groups.
Split split_by_group(const std::vector<int>& members, const std::vector<std::string>& groups,
                     std::array<double, 3> fractions, std::mt19937_64& rng) {
  std::vector<std::string> order;
  std::map<std::string, std::vector<int>> by_group;
  for (int i : members) {
    auto& list = by_group[groups[static_cast<std::size_t>(i)]];
    if (list.empty()) order.push_back(groups[static_cast<std::size_t>(i)]);
    list.push_back(i);
  }
  for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[draw(rng, i)]);
  Split split;
  std::array<std::vector<int>*, 3> parts{&split.train, &split.val, &split.test};
  const double total = static_cast<double>(members.size());
  for (const auto& group : order) {
    int best = 0;
    double best_deficit = -1e300;
    for (int s = 0; s < 3; ++s) {
      if (fractions[static_cast<std::size_t>(s)] <= 0) continue;
      const double deficit = fractions[static_cast<std::size_t>(s)] * total -
                             static_cast<double>(parts[static_cast<std::size_t>(s)]->size());
      if (deficit > best_deficit) best = s, best_deficit = deficit;
    }
    for (int i : by_group[group]) parts[static_cast<std::size_t>(best)]->push_back(i);
  }
  for (auto* p : parts) std::sort(p->begin(), p->end());
  return split;
}

}  // namespace

std::map<std::string, Split> make_splits(const std::vector<std::string>& groups,
                                         const std::vector<std::string>& skeletons,
                                         const std::vector<std::string>& sources,
                                         const SplitOptions& options) {
  if (groups.size() != skeletons.size() || groups.size() != sources.size()) {
    throw Error("make_splits: " + std::to_string(groups.size()) + " groups but " +
                std::to_string(skeletons.size()) + " skeleton families and " +
                std::to_string(sources.size()) + " sources");
  }
  std::map<std::string, Split> out;
  const int n = static_cast<int>(groups.size());
  std::vector<int> all(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) all[static_cast<std::size_t>(i)] = i;
  std::mt19937_64 rng(options.seed);
  out["random"] = split_by_group(all, groups, options.fractions, rng);

  // Test = the characters `held` selects; train / val from the rest in the train : val ratio.
  const auto hold_out = [&](const std::vector<bool>& held, std::uint64_t seed,
                            const std::string& what) {
    std::vector<int> rest, test;
    for (int i = 0; i < n; ++i) (held[static_cast<std::size_t>(i)] ? test : rest).push_back(i);
    if (rest.empty()) throw Error(what + ": holding it out leaves nothing to train on");
    const double tv = options.fractions[0] + options.fractions[1];
    std::array<double, 3> ratio{tv > 0 ? options.fractions[0] / tv : 1.0,
                                tv > 0 ? options.fractions[1] / tv : 0.0, 0.0};
    std::mt19937_64 rng2(seed);
    Split split = split_by_group(rest, groups, ratio, rng2);
    split.test = test;
    return split;
  };
  const auto require_present = [](const std::vector<std::string>& values,
                                  const std::string& value, const std::string& what,
                                  const std::string& kind) {
    const std::set<std::string> present(values.begin(), values.end());
    if (present.count(value)) return;
    throw Error(what + " '" + value + "'; " + kind + " present: " + joined(present));
  };

  if (!options.heldout_skeletons.empty()) {
    for (const auto& family : options.heldout_skeletons) {
      require_present(skeletons, family,
                      "splits.heldout_skeletons: no character has skeleton family", "families");
    }
    const std::set<std::string> families(options.heldout_skeletons.begin(),
                                         options.heldout_skeletons.end());
    std::vector<bool> held(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) held[i] = families.count(skeletons[static_cast<std::size_t>(i)]) > 0;
    out["heldout_skeleton"] = hold_out(held, options.seed + 1, "splits.heldout_skeletons");
  }

  std::uint64_t offset = 2;
  for (const auto& [name, left_out] : options.leave_out_sources) {
    const std::string what = "splits.leave_out_sources." + name;
    for (const auto& source : left_out) {
      require_present(sources, source, what + ": no character comes from source", "sources");
    }
    const std::set<std::string> chosen(left_out.begin(), left_out.end());
    std::set<std::string> test_groups;
    for (int i = 0; i < n; ++i) {
      if (chosen.count(sources[static_cast<std::size_t>(i)])) {
        test_groups.insert(groups[static_cast<std::size_t>(i)]);
      }
    }
    std::vector<bool> held(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) held[i] = test_groups.count(groups[static_cast<std::size_t>(i)]) > 0;
    out["leave_out_" + name] = hold_out(held, options.seed + offset++, what);
  }
  return out;
}

Split validate_on_sources(const Split& split, const std::vector<std::string>& groups,
                          const std::vector<std::string>& sources,
                          const std::vector<bool>& augmented,
                          const std::vector<std::string>& val_sources, const std::string& what) {
  if (groups.size() != sources.size() || groups.size() != augmented.size()) {
    throw Error("validate_on_sources: " + std::to_string(groups.size()) + " groups but " +
                std::to_string(sources.size()) + " sources and " +
                std::to_string(augmented.size()) + " augmentation flags");
  }
  std::vector<int> pool(split.train);
  pool.insert(pool.end(), split.val.begin(), split.val.end());
  std::sort(pool.begin(), pool.end());
  std::set<std::string> present;
  for (int i : pool) present.insert(sources.at(static_cast<std::size_t>(i)));
  const std::set<std::string> chosen(val_sources.begin(), val_sources.end());
  for (const auto& source : chosen) {
    if (present.count(source)) continue;
    throw Error(what + ": no training or validation character comes from source '" + source +
                "'; sources there: " + joined(present));
  }
  std::set<std::string> val_groups;
  for (int i : pool) {
    if (chosen.count(sources[static_cast<std::size_t>(i)])) {
      val_groups.insert(groups[static_cast<std::size_t>(i)]);
    }
  }
  Split out;
  out.test = split.test;
  for (int i : pool) {
    const auto k = static_cast<std::size_t>(i);
    if (!val_groups.count(groups[k])) {
      out.train.push_back(i);
    } else if (!augmented[k]) {
      out.val.push_back(i);
    }
  }
  if (std::none_of(out.train.begin(), out.train.end(),
                   [&](int i) { return !augmented[static_cast<std::size_t>(i)]; })) {
    throw Error(what + ": validating on these sources leaves nothing to train on");
  }
  return out;
}

}  // namespace skinlab::data

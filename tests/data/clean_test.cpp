// Cleaning (framework/data/clean.hpp) and splits (framework/data/splits.hpp): drop rules,
// duplicate detection independent of units and order, variant grouping, and splits that never
// divide a group.

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "framework/core/error.hpp"
#include "framework/data/clean.hpp"
#include "framework/data/splits.hpp"
#include "tests/test_util.hpp"

namespace skinlab::data {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

/// A box-like grid surface (n×n quads in the x–y plane, bent in z) with a 5-joint chain up y;
/// vertex v is weighted between the two joints nearest its height, unless `rigid`.
datasets::SourceCharacter sheet(const std::string& name, int n, double bend, bool rigid = false,
                                int joints = 5) {
  datasets::SourceCharacter s;
  s.source = "test";
  s.path = name + ".test";
  s.skeleton = "chain";
  geometry::Character& c = s.character;
  c.name = name;
  c.mesh.V.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = static_cast<double>(i) / n, y = static_cast<double>(j) / n;
      c.mesh.V.row(j * (n + 1) + i) << x, y, bend * x * x;
    }
  }
  c.mesh.F.resize(2 * n * n, 3);
  for (int j = 0, f = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      c.mesh.F.row(f++) << a, a + 1, a + n + 2;
      c.mesh.F.row(f++) << a, a + n + 2, a + n + 1;
    }
  }
  c.skeleton.positions.resize(joints, 3);
  for (int k = 0; k < joints; ++k) {
    c.skeleton.names.push_back("j" + std::to_string(k));
    c.skeleton.parents.push_back(k - 1);
    c.skeleton.positions.row(k) << 0.5, static_cast<double>(k) / (joints - 1), 0;
  }
  c.weights.resize(c.mesh.num_vertices(), joints);
  for (int v = 0; v < c.mesh.num_vertices(); ++v) {
    const double t = c.mesh.V(v, 1) * (joints - 1);
    const int lo = std::min(static_cast<int>(t), joints - 2);
    const double frac = t - lo;
    if (rigid) {
      c.weights.insert(v, frac < 0.5 ? lo : lo + 1) = 1;
    } else {
      c.weights.insert(v, lo) = 1 - frac;
      if (frac > 0) c.weights.insert(v, lo + 1) = frac;
    }
  }
  c.weights.makeCompressed();
  return s;
}

/// The same geometry scaled, moved, with vertices renumbered in reverse and faces reversed.
datasets::SourceCharacter reordered_copy(const datasets::SourceCharacter& s,
                                         const std::string& name) {
  datasets::SourceCharacter out = s;
  out.character.name = name;
  auto& m = out.character.mesh;
  const int nv = m.num_vertices();
  Eigen::MatrixXd V(nv, 3);
  for (int v = 0; v < nv; ++v) V.row(nv - 1 - v) = 3.0 * s.character.mesh.V.row(v).array() + 7.0;
  m.V = V;
  for (int f = 0; f < m.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) m.F(f, k) = nv - 1 - s.character.mesh.F(m.num_faces() - 1 - f, k);
  }
  out.character.skeleton.positions = 3.0 * s.character.skeleton.positions.array() + 7.0;
  return out;
}

TEST(Clean, DropsRigidAndFewBoneCharactersWithReasons) {
  std::vector<datasets::Excluded> excluded;
  auto kept = clean(
      {sheet("blended", 8, 0.0), sheet("rigid", 8, 0.3, true), sheet("three", 8, 0.6, false, 3)},
      CleaningOptions{}, excluded);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].source.character.name, "blended");
  ASSERT_EQ(excluded.size(), 2u);
  EXPECT_EQ(excluded[0].path, "rigid.test");
  EXPECT_NE(excluded[0].reason.find("rigid-only"), std::string::npos) << excluded[0].reason;
  EXPECT_NE(excluded[1].reason.find("3 joint(s), fewer than min_bones = 4"), std::string::npos)
      << excluded[1].reason;

  CleaningOptions keep_rigid;
  keep_rigid.drop_rigid = false;
  keep_rigid.group_similarity = 2;  // grouping off
  excluded.clear();
  EXPECT_EQ(clean({sheet("rigid", 8, 0.3, true)}, keep_rigid, excluded).size(), 1u);
}

TEST(Clean, ConfigExclusionsCarryTheirReasonAndMustNameACharacter) {
  const auto options = CleaningOptions::from(
      config::Config::parse("exclude: {cart: \"a vehicle, not a character\"}").root());
  std::vector<datasets::Excluded> excluded;
  auto kept = clean({sheet("cart", 8, 0.0), sheet("person", 8, 1.0)}, options, excluded);
  ASSERT_EQ(kept.size(), 1u);
  ASSERT_EQ(excluded.size(), 1u);
  EXPECT_EQ(excluded[0].reason, "cart: excluded by the config: a vehicle, not a character");
  EXPECT_THROW(clean({sheet("person", 8, 1.0)}, options, excluded), Error);
}

TEST(Clean, ASkeletonListKeepsOnlyThoseFamilies) {
  const auto options =
      CleaningOptions::from(config::Config::parse("skeletons: [Biped]").root());
  datasets::SourceCharacter human = sheet("human", 8, 0.0), horse = sheet("horse", 8, 1.0);
  human.skeleton = "Biped";
  horse.skeleton = "Horse";
  std::vector<datasets::Excluded> excluded;
  auto kept = clean({horse, human}, options, excluded);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].source.character.name, "human");
  ASSERT_EQ(excluded.size(), 1u);
  EXPECT_EQ(excluded[0].reason, "horse: skeleton family 'Horse' is not in cleaning.skeletons");
}

TEST(Clean, DuplicateHashIgnoresUnitsPlacementAndOrder) {
  const auto a = sheet("a", 6, 0.4);
  const auto b = reordered_copy(a, "b");
  EXPECT_EQ(geometry_hash(a.character, 1e-4), geometry_hash(b.character, 1e-4));
  EXPECT_NE(geometry_hash(a.character, 1e-4), geometry_hash(sheet("c", 6, 0.41).character, 1e-4));

  std::vector<datasets::Excluded> excluded;
  auto kept = clean({a, b}, CleaningOptions{}, excluded);
  ASSERT_EQ(kept.size(), 1u);
  ASSERT_EQ(excluded.size(), 1u);
  EXPECT_EQ(excluded[0].reason, "b: duplicate geometry of a");
}

TEST(Clean, GroupsNearIdenticalMeshesOnTheSameSkeletonOnly) {
  // A slightly different bend is a variant; a strongly bent sheet is another character; the
  // same mesh on another skeleton family is never grouped.
  auto other_family = sheet("other_family", 8, 0.02);
  other_family.skeleton = "other";
  std::vector<datasets::Excluded> excluded;
  auto kept =
      clean({sheet("base", 8, 0.0), sheet("variant", 8, 0.01), sheet("bent", 8, 1.0), other_family},
            CleaningOptions{}, excluded);
  ASSERT_EQ(kept.size(), 4u);
  std::map<std::string, std::string> group;
  for (const auto& k : kept) group[k.source.character.name] = k.group;
  EXPECT_EQ(group["base"], "base");
  EXPECT_EQ(group["variant"], "base");
  EXPECT_EQ(group["bent"], "bent");
  EXPECT_EQ(group["other_family"], "other_family");

  const auto& base = kept[0].source.character;
  EXPECT_DOUBLE_EQ(surface_similarity(base, base, 1.0 / 32), 1.0);
  EXPECT_LT(surface_similarity(base, kept[2].source.character, 1.0 / 128), 0.99);
}

TEST(Splits, NeverDivideAGroupAndApproachTheFractions) {
  // 40 characters in 25 groups of sizes 1–3 over 4 skeleton families.
  std::vector<std::string> groups, skeletons;
  for (int g = 0; g < 25; ++g) {
    for (int k = 0; k < 1 + (g % 3 == 0 ? 2 : g % 2); ++k) {
      groups.push_back("g" + std::to_string(g));
      skeletons.push_back("family" + std::to_string(g % 4));
    }
  }
  // Sources: groups 0–4 come from "b", the rest from "a"; group 5 has a copy in "b" too.
  std::vector<std::string> sources;
  for (const auto& g : groups) {
    const int k = std::stoi(g.substr(1));
    sources.push_back(k < 5 ? "b" : "a");
  }
  for (std::size_t i = 0; i < groups.size(); ++i) {
    if (groups[i] == "g5") {
      sources[i] = "b";
      break;
    }
  }
  SplitOptions options;
  options.heldout_skeletons = {"family3"};
  options.leave_out_sources = {{"b_only", {"b"}}};
  const auto splits = make_splits(groups, skeletons, sources, options);
  ASSERT_EQ(splits.size(), 3u);
  for (const auto& [name, s] : splits) {
    std::map<std::string, int> part_of_group;
    std::set<int> seen;
    int part = 0;
    for (const auto* list : {&s.train, &s.val, &s.test}) {
      for (int i : *list) {
        EXPECT_TRUE(seen.insert(i).second) << name << ": character " << i << " twice";
        auto [it, inserted] = part_of_group.try_emplace(groups[static_cast<std::size_t>(i)], part);
        EXPECT_EQ(it->second, part) << name << ": group " << it->first << " is divided";
      }
      ++part;
    }
    EXPECT_EQ(seen.size(), groups.size()) << name;
  }
  const Split& r = splits.at("random");
  const double n = static_cast<double>(groups.size());
  EXPECT_NEAR(r.train.size() / n, 0.7, 0.08);
  EXPECT_NEAR(r.val.size() / n, 0.1, 0.08);
  EXPECT_NEAR(r.test.size() / n, 0.2, 0.08);
  const Split& h = splits.at("heldout_skeleton");
  for (int i : h.test) EXPECT_EQ(skeletons[static_cast<std::size_t>(i)], "family3");
  for (int i : h.train) EXPECT_NE(skeletons[static_cast<std::size_t>(i)], "family3");
  EXPECT_FALSE(h.val.empty());
  // Leaving out source "b": its characters are tested, and group g5 (one member in "b") whole.
  const Split& l = splits.at("leave_out_b_only");
  std::set<std::string> test_groups;
  for (int i : l.test) test_groups.insert(groups[static_cast<std::size_t>(i)]);
  EXPECT_EQ(test_groups, (std::set<std::string>{"g0", "g1", "g2", "g3", "g4", "g5"}));
  for (int i : l.train) EXPECT_EQ(sources[static_cast<std::size_t>(i)], "a");
  EXPECT_FALSE(l.val.empty());

  // Same seed, same splits; another seed, other splits.
  EXPECT_EQ(make_splits(groups, skeletons, sources, options).at("random").test, r.test);
  options.seed = 7;
  EXPECT_NE(make_splits(groups, skeletons, sources, options).at("random").test, r.test);
}

TEST(Splits, UnknownHeldOutFamilyIsAnErrorListingTheFamilies) {
  SplitOptions options;
  options.heldout_skeletons = {"elephnt"};
  try {
    make_splits({"a", "b"}, {"elephant", "horse"}, {"s", "s"}, options);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'elephnt'; families present: elephant, horse"),
              std::string::npos)
        << e.what();
  }
  options.heldout_skeletons = {"elephant", "horse"};
  EXPECT_THROW(make_splits({"a", "b"}, {"elephant", "horse"}, {"s", "s"}, options), Error);
  options.heldout_skeletons.clear();
  options.leave_out_sources = {{"games", {"zeroad", "sumwars"}}};
  testing::expect_error<Error>(
      [&] { make_splits({"a", "b"}, {"elephant", "horse"}, {"zeroad", "folder"}, options); },
      {"splits.leave_out_sources.games", "'sumwars'", "sources present: folder, zeroad"});
  options.leave_out_sources = {{"all", {"zeroad", "folder"}}};
  testing::expect_error<Error>(
      [&] { make_splits({"a", "b"}, {"elephant", "horse"}, {"zeroad", "folder"}, options); },
      {"leave_out_sources.all", "nothing to train on"});
}

TEST(Splits, ValidationOnSourcesMovesWholeGroupsAndDropsTheirAugmentedCopies) {
  // 0-5 train (5 an augmented copy of 0), 6-7 val, 8 test; "q" holds 0, 6 and the test 8;
  // 1 shares 0's group.
  const data::Split split{{0, 1, 2, 3, 4, 5}, {6, 7}, {8}};
  const std::vector<std::string> groups{"a", "a", "b", "c", "d", "a", "e", "f", "g"};
  const std::vector<std::string> sources{"q", "r", "r", "r", "r", "q", "q", "r", "q"};
  const std::vector<bool> augmented{false, false, false, false, false, true, false, false, false};
  const data::Split s = validate_on_sources(split, groups, sources, augmented, {"q"}, "x");
  EXPECT_EQ(s.val, (std::vector<int>{0, 1, 6}));
  EXPECT_EQ(s.train, (std::vector<int>{2, 3, 4, 7}));
  EXPECT_EQ(s.test, (std::vector<int>{8}));
  testing::expect_error<Error>(
      [&] { validate_on_sources(split, groups, sources, augmented, {"z"}, "x"); },
      {"x: no training or validation character comes from source 'z'", "sources there: q, r"});
  // Only an augmented copy would be left to train: that is nothing to train on.
  testing::expect_error<Error>(
      [&] {
        validate_on_sources({{5}, {2}, {}}, groups, sources, augmented, {"r"}, "x");
      },
      {"x: validating on these sources leaves nothing to train on"});
}

TEST(Splits, OptionsAreValidated) {
  auto parse = [](const std::string& yaml) {
    return SplitOptions::from(config::Config::parse(yaml).root());
  };
  EXPECT_EQ(parse("seed: 3").seed, 3u);
  EXPECT_THROW(parse("fractions: [0.5, 0.1, 0.1]"), ConfigError);
  EXPECT_THROW(parse("fractions: [0.9, 0.1]"), ConfigError);
  EXPECT_THROW(parse("heldout: [bird]"), ConfigError);
  const auto leave = parse("leave_out_sources: {ogre_games: [sumwars, opendungeons], zeroad: [zeroad]}");
  EXPECT_EQ(leave.leave_out_sources.at("ogre_games"),
            (std::vector<std::string>{"sumwars", "opendungeons"}));
  EXPECT_THROW(parse("leave_out_sources: [zeroad]"), ConfigError);
  EXPECT_THROW(parse("leave_out_sources: {none: []}"), ConfigError);
  EXPECT_THROW(CleaningOptions::from(config::Config::parse("min_bone: 3").root()), ConfigError);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::data

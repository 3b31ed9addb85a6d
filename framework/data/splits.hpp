#pragma once
/// \file
/// Train / validation / test splits of a dataset, written to `/splits/<name>`
/// of the dataset file (datasets/FORMAT.md) by `skinlab prepare`.
///
/// - `random`: variant groups (clean.hpp) are shuffled with the seed and assigned one by one to
///   the split furthest below its target share of characters (fractions 0.7 / 0.1 / 0.2 by
///   default; ties go to the earlier split), so no group is ever divided and the shares come as
///   close to the fractions as the group sizes allow.
/// - `heldout_skeleton` (only when `heldout_skeletons` is not empty): every character whose
///   skeleton family is listed goes to test; the others are split into train / val by groups as
///   above, in the ratio of the train and val fractions. It measures generalisation to skeletons
///   never seen in training (e.g. no elephant and no bird in training).
/// - `leave_out_<name>`, one per entry of `leave_out_sources` (name → source keys): every
///   character of those sources goes to test, the others are split into train / val as above.
///   A variant group with a member in a left-out source goes to test whole, so a near-copy of a
///   test character in another source (the cleaning groups duplicates across sources) never
///   trains. It measures generalisation to a game never seen in training, the project's proxy
///   for a user's own character.
///
/// A run can also judge its training on sources it never trains on: validate_on_sources (the
/// `data.val_sources` of a run config) moves the variant groups of chosen sources from a split's
/// train and val parts into a new val part, without preparing the file again.
///
/// The shuffle is our own Fisher–Yates over std::mt19937_64 with an explicit integer draw, so a
/// seed gives the same splits with every standard library.

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/data/dataset_file.hpp"

namespace skinlab::data {

struct SplitOptions {
  std::uint64_t seed = 0;
  std::array<double, 3> fractions{0.7, 0.1, 0.2};  ///< train, val, test; sum 1
  std::vector<std::string> heldout_skeletons;      ///< skeleton families only in test
  /// split name → sources (SourceCharacter::source) whose characters form its test part
  std::map<std::string, std::vector<std::string>> leave_out_sources;

  /// Decodes a `splits:` map (every field optional); errors name the file, line and key.
  static SplitOptions from(const config::Node& node);
};

/// Splits characters given their group, skeleton family and source (parallel lists) as the file
/// comment says. Throws Error when a held-out family or left-out source is not present (listing
/// those present) or when holding it out would leave no character for training.
std::map<std::string, Split> make_splits(const std::vector<std::string>& groups,
                                         const std::vector<std::string>& skeletons,
                                         const std::vector<std::string>& sources,
                                         const SplitOptions& options);

/// `split` with its validation part drawn from sources instead of at random: every character of
/// its train and val parts whose variant group (`groups`, parallel to `sources` and `augmented`)
/// has a member from one of `val_sources` validates, the rest of both parts trains, and augmented
/// copies (`augmented[i]`) of validating characters are dropped (a copy only ever trains). The
/// test part is unchanged. With a leave-one-source-out split this makes early stopping and model
/// choices (such as prior_kl's β) look at a game the model never trained on, as the test does.
/// Throws Error, starting with `what`, when a source has no character in the train and val parts
/// (listing the sources they have) or when nothing would be left to train on.
Split validate_on_sources(const Split& split, const std::vector<std::string>& groups,
                          const std::vector<std::string>& sources,
                          const std::vector<bool>& augmented,
                          const std::vector<std::string>& val_sources, const std::string& what);

}  // namespace skinlab::data

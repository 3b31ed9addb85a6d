#pragma once
/// \file
/// Candidate coverage: how much of the artist weights the K nearest bones of a distance can
/// express, for every K at once (HeterSkinNet Sec. 4.1 and Fig. 6, on which the paper chose
/// K = 3: "the vertices are bound to their Top-3 nearest bones with more than 90% of total skin
/// weights, and the influential bones among these bones account for 90% total influential
/// bones").
///
/// Per vertex, the bones are ranked by the stored distance D (ascending, ties to the lower bone
/// index: the order of top_k_bones, preprocess.hpp), and the artist weights are taken at bone
/// level by the preprocessing's own rule (bone_weights, preprocess.hpp). Then, pooled over the
/// vertices and characters given:
///
///     weight coverage(K) = Σ_v Σ_{rank(v, b) < K} w(v, b) / Σ_v Σ_b w(v, b)     (blue, Fig. 6)
///     entry coverage(K)  = |{(v, b) : w(v, b) > 1e-4, rank(v, b) < K}| / |{w(v, b) > 1e-4}|
///                                                                               (orange, Fig. 6)
///
/// Entry coverage at the K a dataset was prepared with is the highest recall any method that
/// predicts over the K candidates can reach (before pruning).
///
/// Where influential entries fall outside the K candidates, `Coverage` also says what took their
/// place: whether the missed bone is a leaf's helper bone, whether it ties in distance with the
/// K-th candidate, and how many candidate slots went to bones whose start joint carries no weight
/// anywhere on the character (weightless end, control or prop joints).

#include <string>
#include <vector>

#include "framework/data/dataset_file.hpp"

namespace skinlab::data {

/// Influence threshold of the coverage figures (HeterSkinNet Sec. 4.2; precision_recall's).
inline constexpr double kInfluential = 1e-4;

struct Coverage {
  int max_k = 0;
  /// [K − 1] for K = 1..max_k: artist weight, and influential entries, on the K nearest bones.
  std::vector<double> weight_within;
  std::vector<long> entries_within;
  double weight = 0;  ///< all artist weight (Σ over vertices of the row sums, ≈ #V)
  long entries = 0;   ///< all influential entries
  long vertices = 0;
  // Diagnostics of the entries missed at K = `diagnose_k`.
  int diagnose_k = 0;
  long missed = 0;            ///< influential entries outside the diagnose_k nearest bones
  long missed_helper = 0;     ///< ... whose bone is a leaf's helper bone
  long missed_tied = 0;       ///< ... whose distance equals the diagnose_k-th candidate's
  long slots = 0;             ///< candidate slots (vertices × min(diagnose_k, #B))
  long weightless_slots = 0;  ///< ... taken by a bone whose start joint has no weight at all

  /// entries_within[K − 1] / entries (0 without entries).
  double entry_share(int k) const;
  /// weight_within[K − 1] / weight (0 without weight).
  double weight_share(int k) const;
  /// Adds another character's (or set's) counts; max_k and diagnose_k must agree.
  void add(const Coverage& other);
};

/// Coverage of `character` under its stored distance `distance` for K = 1..max_k, with the
/// missed entries diagnosed at `diagnose_k`. Throws Error naming the character when the
/// distance is not stored or the character has no weights, and for max_k < 1 or diagnose_k
/// outside [1, max_k].
Coverage candidate_coverage(const PreparedCharacter& character, const std::string& distance,
                            int max_k, int diagnose_k);

}  // namespace skinlab::data

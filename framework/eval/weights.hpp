#pragma once
/// \file
/// What the metrics share (not a plug-in): reading one character's predicted and ground-truth
/// bone weights out of MetricInputs (the one torch → Eigen step of framework/eval), pruning a
/// prediction as the compared methods' post-processing does (HeterSkinNet Sec. 4.5), and mapping
/// bone weights back to joints for skinning (data/preprocess.hpp, bone-level rule).

#include <string>

#include "framework/data/dataset_file.hpp"
#include "framework/eval/metric.hpp"
#include "framework/geometry/skin_weights.hpp"
#include "framework/infer/map_back.hpp"

namespace skinlab::eval {

using data::RowMatrixXd;
using data::RowMatrixXi;

/// The two #V×#B weight matrices of one character, in double precision.
struct WeightPair {
  RowMatrixXd pred;
  RowMatrixXd target;
};

/// Checks `in.pred` and `in.target` and copies them into Eigen (float64). Throws c10::Error
/// (TORCH_CHECK), naming `metric` and the character when one is given, for: an undefined tensor,
/// a tensor that is not 2-D or not floating point, shapes that differ (both shapes named), a
/// non-finite or negative weight (vertex and bone named), and, when `in.character` is set, a
/// vertex or bone count that differs from the character's (both named). Row sums are not checked:
/// a prediction scattered from K candidates may leave a row short of 1.
WeightPair read_weights(const MetricInputs& in, const std::string& metric);

/// "metric 'name'" or "metric 'name' (character 'c')": the prefix of every metric error.
std::string error_context(const MetricInputs& in, const std::string& metric);

/// The 0.25 pruning of HeterSkinNet Sec. 4.5 (infer/map_back.hpp, shared with prediction).
using infer::prune_rows;

/// #V×#J joint weights from #V×#B bone weights W. A bone moves with its start joint, so
///     W_J(v, j) = Σ_{b : bones(b, 0) = j} W(v, b),
/// which undoes the bone-level rule of data/preprocess.hpp (artist joint weights → bone
/// weights) exactly. `bones` is #B×2 (start, end) joint indices in [0, num_joints). Zero entries
/// are not stored.
geometry::SparseWeights joint_weights(const RowMatrixXd& W, const RowMatrixXi& bones,
                                      int num_joints);

}  // namespace skinlab::eval

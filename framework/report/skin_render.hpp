#pragma once
/// \file
/// Pictures of a skinning result for `skinlab predict --render`: the mesh from the front (+Z)
/// and the side (+X), every vertex coloured by its most influential bone (a fixed categorical
/// colour per bone index, so the same bone has the same colour in every picture of one
/// skeleton), and optionally a second row with the per-vertex L1 error Σ_b |P − G| against
/// ground-truth weights (HeterSkinNet Fig. 7/10, viridis from 0 to `l1_max`, with a colour bar).

#include <Eigen/Core>
#include <filesystem>

#include "framework/report/plot.hpp"

namespace skinlab::report {

/// Colour of bone `b`: hues spaced by the golden angle at two saturation/value levels, so
/// neighbouring indices differ clearly.
Rgb bone_colour(int b);

struct SkinRenderOptions {
  int width = 240, height = 320;  ///< of each view
  double l1_max = 1.0;            ///< top of the error scale (Σ|P − G| lies in [0, 2])
};

/// Renders V (#V×3, Y up) and F with per-vertex bone weights W (#V×#B) and, when `truth` has
/// rows, the error row against it (#V×#B). Throws std::invalid_argument on size mismatches.
Image render_skin(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Eigen::MatrixXd& W,
                  const Eigen::MatrixXd& truth = {}, const SkinRenderOptions& options = {});

}  // namespace skinlab::report

#pragma once
/// \file
/// Per-vertex error figures for generated reports (HeterSkinNet Fig. 7 and 10: per-vertex L1
/// errors of the weights; Fig. 8-style deformation error maps): a colour map, an orthographic
/// z-buffered rendering of a mesh coloured per vertex, a colour bar, and an ASCII PLY file with
/// vertex colours and the scalar itself, so a figure can be opened in MeshLab or Blender as well
/// as viewed as a PNG. No window system and no GPU: a scanline-free rasteriser over pixel
/// bounding boxes with edge functions, which is ample for meshes of a few thousand triangles.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "framework/report/plot.hpp"

namespace skinlab::report {

/// Viridis (matplotlib's perceptually uniform map), piecewise linear through 9 samples;
/// t is clamped to [0, 1]; 0 is dark purple, 1 yellow.
Rgb viridis(double t);

/// Per-vertex colours of `values` mapped through viridis on [0, vmax] (vmax > 0).
std::vector<Rgb> colour_values(const std::vector<double>& values, double vmax);

struct RenderOptions {
  int width = 240, height = 320;
  /// Rotation of the camera about the vertical (Y) axis, degrees: 0 looks at the −Z face of
  /// the mesh from +Z ("front" for a character facing +Z), 90 from +X.
  double azimuth_degrees = 0;
  int margin = 8;  ///< pixels left free on every side
  Rgb background = {255, 255, 255};
};

/// Orthographic rendering of the triangle mesh (V #V×3 with Y up, F #F×3) from the camera of
/// `options`, scaled to fit. Colours are interpolated over each triangle from `colours` (#V)
/// and shaded two-sided by the face's facing ratio (0.35 + 0.65 |n·view|), so winding does not
/// matter. Nearest surface wins (z-buffer). Throws std::invalid_argument on size mismatches or
/// a face index outside [0, #V).
Image render_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                  const std::vector<Rgb>& colours, const RenderOptions& options = {});

/// The front view (azimuth 0) above the side view (azimuth 90) of one coloured mesh, 4 pixels
/// apart: one column of an error-map figure.
Image front_and_side(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                     const std::vector<Rgb>& colours);

/// The value at quantile q ∈ [0, 1] of `values` (the element at rank ⌊q·(n−1)⌋; 0 when empty):
/// an error map's scale top that a few outliers do not set.
double quantile(std::vector<double> values, double q);

/// A horizontal viridis bar `width`×`height` pixels (plus tick labels below it) labelled at 0,
/// vmax/2 and vmax with `decimals` digits after the point.
Image colour_bar(int width, int height, double vmax, int decimals);

/// `images` left to right with `gap` pixels between them, top-aligned, on white; then `below`
/// (if it has pixels) centred under them.
Image compose_row(const std::vector<Image>& images, int gap, const Image* below = nullptr);
/// `rows` top to bottom with `gap` pixels between them, left-aligned, on white.
Image compose_column(const std::vector<Image>& rows, int gap);

/// Writes an ASCII PLY (format ascii 1.0) with vertex x y z, uchar red green blue, and a float
/// property `scalar_name` holding `values` (#V), and the faces; atomically. Throws IoError, or
/// std::invalid_argument for size mismatches.
void write_coloured_ply(const std::filesystem::path& file, const Eigen::MatrixXd& V,
                        const Eigen::MatrixXi& F, const std::vector<Rgb>& colours,
                        const std::string& scalar_name, const std::vector<double>& values,
                        const std::string& comment = "");

}  // namespace skinlab::report

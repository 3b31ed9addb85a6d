#include "framework/report/skin_render.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

#include "framework/report/mesh_figure.hpp"

namespace skinlab::report {

namespace {

Rgb hsv(double h, double s, double v) {
  const double c = v * s, hp = std::fmod(h, 1.0) * 6.0, x = c * (1 - std::abs(std::fmod(hp, 2.0) - 1));
  double r = 0, g = 0, b = 0;
  if (hp < 1) r = c, g = x;
  else if (hp < 2) r = x, g = c;
  else if (hp < 3) g = c, b = x;
  else if (hp < 4) g = x, b = c;
  else if (hp < 5) r = x, b = c;
  else r = c, b = x;
  const double m = v - c;
  auto byte = [&](double t) { return static_cast<std::uint8_t>(std::lround(255.0 * (t + m))); };
  return {byte(r), byte(g), byte(b)};
}

}  // namespace

Rgb bone_colour(int b) {
  const double golden = 0.6180339887498949;
  return b % 2 == 0 ? hsv(b * golden, 0.75, 0.95) : hsv(b * golden, 0.55, 0.75);
}

Image render_skin(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const Eigen::MatrixXd& W,
                  const Eigen::MatrixXd& truth, const SkinRenderOptions& options) {
  if (W.rows() != V.rows()) throw std::invalid_argument("render_skin: W must have #V rows");
  const bool errors = truth.rows() > 0;
  if (errors && (truth.rows() != W.rows() || truth.cols() != W.cols())) {
    throw std::invalid_argument("render_skin: ground truth must be #V×#B like W");
  }
  std::vector<Rgb> bones(static_cast<std::size_t>(V.rows()));
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    Eigen::Index best = 0;
    W.row(v).maxCoeff(&best);
    bones[static_cast<std::size_t>(v)] = bone_colour(static_cast<int>(best));
  }
  RenderOptions front;
  front.width = options.width;
  front.height = options.height;
  RenderOptions side = front;
  side.azimuth_degrees = 90;
  std::vector<Image> rows = {
      compose_row({render_mesh(V, F, bones, front), render_mesh(V, F, bones, side)}, 4)};
  if (errors) {
    std::vector<double> e(static_cast<std::size_t>(V.rows()));
    for (Eigen::Index v = 0; v < V.rows(); ++v) {
      e[static_cast<std::size_t>(v)] = (W.row(v) - truth.row(v)).cwiseAbs().sum();
    }
    const auto colours = colour_values(e, options.l1_max);
    const Image bar = colour_bar(2 * options.width, 12, options.l1_max, 2);
    rows.push_back(compose_row(
        {render_mesh(V, F, colours, front), render_mesh(V, F, colours, side)}, 4, &bar));
  }
  return compose_column(rows, 6);
}

}  // namespace skinlab::report

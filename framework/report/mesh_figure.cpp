#include "framework/report/mesh_figure.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "framework/core/atomic_file.hpp"

namespace skinlab::report {

namespace {

// Viridis at t = 0, 1/8, ..., 1 (matplotlib's _viridis_data, rounded to 8 bits).
constexpr std::array<std::array<double, 3>, 9> kViridis = {{{68, 1, 84},
                                                            {71, 44, 122},
                                                            {59, 81, 139},
                                                            {44, 113, 142},
                                                            {33, 144, 141},
                                                            {39, 173, 129},
                                                            {92, 200, 99},
                                                            {170, 220, 50},
                                                            {253, 231, 37}}};

std::uint8_t to_byte(double v) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
}

}  // namespace

Rgb viridis(double t) {
  if (!std::isfinite(t)) t = 0;
  t = std::clamp(t, 0.0, 1.0) * 8.0;
  const int i = std::min(static_cast<int>(t), 7);
  const double f = t - i;
  Rgb c;
  for (int k = 0; k < 3; ++k) c[k] = to_byte(kViridis[i][k] * (1 - f) + kViridis[i + 1][k] * f);
  return c;
}

std::vector<Rgb> colour_values(const std::vector<double>& values, double vmax) {
  if (!(vmax > 0)) throw std::invalid_argument("colour_values: vmax must be positive");
  std::vector<Rgb> out;
  out.reserve(values.size());
  for (double v : values) out.push_back(viridis(v / vmax));
  return out;
}

Image render_mesh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                  const std::vector<Rgb>& colours, const RenderOptions& options) {
  if (V.cols() != 3 || F.cols() != 3 || static_cast<Eigen::Index>(colours.size()) != V.rows()) {
    throw std::invalid_argument(fmt::format(
        "render_mesh: expected #V×3 vertices, #F×3 faces and #V colours, got {}×{}, {}×{}, {}",
        V.rows(), V.cols(), F.rows(), F.cols(), colours.size()));
  }
  if (F.size() > 0 && (F.minCoeff() < 0 || F.maxCoeff() >= V.rows())) {
    throw std::invalid_argument("render_mesh: a face index is outside the vertex range");
  }
  Image image(options.width, options.height, options.background);
  if (V.rows() == 0 || F.rows() == 0) return image;

  // Camera frame: rotate the mesh by −azimuth about Y, then look along −Z.
  const double a = options.azimuth_degrees * M_PI / 180.0;
  Eigen::Matrix3d r;
  r << std::cos(a), 0, -std::sin(a), 0, 1, 0, std::sin(a), 0, std::cos(a);
  const Eigen::MatrixXd P = V * r.transpose();
  const Eigen::RowVector3d lo = P.colwise().minCoeff(), hi = P.colwise().maxCoeff();
  const double span_x = std::max(hi(0) - lo(0), 1e-12), span_y = std::max(hi(1) - lo(1), 1e-12);
  const double usable_w = options.width - 2.0 * options.margin;
  const double usable_h = options.height - 2.0 * options.margin;
  const double scale = std::min(usable_w / span_x, usable_h / span_y);
  const double ox = options.margin + (usable_w - scale * span_x) / 2;
  const double oy = options.margin + (usable_h - scale * span_y) / 2;
  // Pixel coordinates (x right, y down) and depth (larger is nearer the camera).
  Eigen::MatrixXd S(P.rows(), 3);
  S.col(0) = ((P.col(0).array() - lo(0)) * scale + ox).matrix();
  S.col(1) = ((hi(1) - P.col(1).array()) * scale + oy).matrix();
  S.col(2) = P.col(2);

  std::vector<double> depth(static_cast<std::size_t>(options.width) * options.height,
                            -std::numeric_limits<double>::infinity());
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const int i0 = F(f, 0), i1 = F(f, 1), i2 = F(f, 2);
    const double x0 = S(i0, 0), y0 = S(i0, 1), x1 = S(i1, 0), y1 = S(i1, 1), x2 = S(i2, 0),
                 y2 = S(i2, 1);
    const double area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
    if (std::abs(area) < 1e-12) continue;
    const Eigen::Vector3d e1 = (P.row(i1) - P.row(i0)).transpose();
    const Eigen::Vector3d e2 = (P.row(i2) - P.row(i0)).transpose();
    const Eigen::Vector3d n = e1.cross(e2);
    const double facing = n.norm() > 0 ? std::abs(n.z()) / n.norm() : 0;
    const double shade = 0.35 + 0.65 * facing;
    const int px0 = std::max(0, static_cast<int>(std::floor(std::min({x0, x1, x2}))));
    const int px1 =
        std::min(options.width - 1, static_cast<int>(std::ceil(std::max({x0, x1, x2}))));
    const int py0 = std::max(0, static_cast<int>(std::floor(std::min({y0, y1, y2}))));
    const int py1 =
        std::min(options.height - 1, static_cast<int>(std::ceil(std::max({y0, y1, y2}))));
    for (int py = py0; py <= py1; ++py) {
      for (int px = px0; px <= px1; ++px) {
        const double cx = px + 0.5, cy = py + 0.5;
        // Barycentric coordinates by edge functions; a pixel centre on an edge counts.
        const double b0 = ((x1 - cx) * (y2 - cy) - (x2 - cx) * (y1 - cy)) / area;
        const double b1 = ((x2 - cx) * (y0 - cy) - (x0 - cx) * (y2 - cy)) / area;
        const double b2 = 1 - b0 - b1;
        if (b0 < -1e-9 || b1 < -1e-9 || b2 < -1e-9) continue;
        const double z = b0 * S(i0, 2) + b1 * S(i1, 2) + b2 * S(i2, 2);
        double& zbuf = depth[static_cast<std::size_t>(py) * options.width + px];
        if (z <= zbuf) continue;
        zbuf = z;
        Rgb c;
        for (int k = 0; k < 3; ++k) {
          c[k] = to_byte(shade * (b0 * colours[i0][k] + b1 * colours[i1][k] + b2 * colours[i2][k]));
        }
        image.set(px, py, c);
      }
    }
  }
  return image;
}

Image colour_bar(int width, int height, double vmax, int decimals) {
  constexpr int kScale = 2, kGlyph = 5 * kScale;
  Image bar(width, height + 4 + kGlyph);
  for (int x = 0; x < width; ++x) {
    bar.fill_rect(x, 0, x, height - 1, viridis(width > 1 ? x / (width - 1.0) : 0.0));
  }
  for (int tick = 0; tick <= 2; ++tick) {
    const std::string label = fmt::format("{:.{}f}", vmax * tick / 2.0, decimals);
    const int w = Image::text_width(label, kScale);
    const int centre = tick * (width - 1) / 2;
    bar.text(std::clamp(centre - w / 2, 0, std::max(0, width - w)), height + 4, label, kScale,
             {0, 0, 0});
  }
  return bar;
}

Image compose_row(const std::vector<Image>& images, int gap, const Image* below) {
  int width = 0, height = 0;
  for (const Image& im : images) {
    width += im.width + (width > 0 ? gap : 0);
    height = std::max(height, im.height);
  }
  const bool has_below = below != nullptr && below->width > 0 && below->height > 0;
  if (has_below) width = std::max(width, below->width);
  Image out(std::max(width, 1), std::max(height + (has_below ? gap + below->height : 0), 1));
  int x = 0;
  for (const Image& im : images) {
    out.paste(im, x, 0);
    x += im.width + gap;
  }
  if (has_below) out.paste(*below, (width - below->width) / 2, height + gap);
  return out;
}

Image front_and_side(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                     const std::vector<Rgb>& colours) {
  RenderOptions front, side;
  side.azimuth_degrees = 90;
  return compose_column({render_mesh(V, F, colours, front), render_mesh(V, F, colours, side)}, 4);
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

Image compose_column(const std::vector<Image>& rows, int gap) {
  int width = 0, height = 0;
  for (const Image& im : rows) {
    width = std::max(width, im.width);
    height += im.height + (height > 0 ? gap : 0);
  }
  Image out(std::max(width, 1), std::max(height, 1));
  int y0 = 0;
  for (const Image& im : rows) {
    out.paste(im, 0, y0);
    y0 += im.height + gap;
  }
  return out;
}

void write_coloured_ply(const std::filesystem::path& file, const Eigen::MatrixXd& V,
                        const Eigen::MatrixXi& F, const std::vector<Rgb>& colours,
                        const std::string& scalar_name, const std::vector<double>& values,
                        const std::string& comment) {
  if (V.cols() != 3 || F.cols() != 3 || static_cast<Eigen::Index>(colours.size()) != V.rows() ||
      static_cast<Eigen::Index>(values.size()) != V.rows()) {
    throw std::invalid_argument(
        "write_coloured_ply: expected #V×3 vertices, #F×3 faces, #V "
        "colours and #V values");
  }
  std::string out = "ply\nformat ascii 1.0\n";
  if (!comment.empty()) out += "comment " + comment + "\n";
  out += fmt::format(
      "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float {}\n"
      "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
      V.rows(), scalar_name, F.rows());
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    out += fmt::format("{:.6g} {:.6g} {:.6g} {} {} {} {:.6g}\n", V(v, 0), V(v, 1), V(v, 2),
                       colours[v][0], colours[v][1], colours[v][2], values[v]);
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    out += fmt::format("3 {} {} {}\n", F(f, 0), F(f, 1), F(f, 2));
  }
  write_file_atomic(file, out);
}

}  // namespace skinlab::report

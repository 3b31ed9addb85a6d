// Error-map figures (framework/report/mesh_figure.hpp): the colour map's ends, the rasteriser's
// coverage, colour interpolation and z-buffer from two camera directions, composition sizes,
// and the PLY file's header and rows.

#include "framework/report/mesh_figure.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "../test_util.hpp"

namespace skinlab::report {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

Rgb pixel(const Image& im, int x, int y) {
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * im.width + x);
  return {im.pixels[i], im.pixels[i + 1], im.pixels[i + 2]};
}

int count_not(const Image& im, Rgb background) {
  int n = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) n += pixel(im, x, y) != background;
  return n;
}

TEST(Viridis, EndsAndClamping) {
  EXPECT_EQ(viridis(0), (Rgb{68, 1, 84}));
  EXPECT_EQ(viridis(1), (Rgb{253, 231, 37}));
  EXPECT_EQ(viridis(-3), viridis(0));
  EXPECT_EQ(viridis(7), viridis(1));
  EXPECT_EQ(viridis(std::nan("")), viridis(0));
  // Green rises monotonically along the map (its lightness channel, roughly).
  for (int i = 1; i <= 100; ++i) EXPECT_GE(viridis(i / 100.0)[1], viridis((i - 1) / 100.0)[1]);
  EXPECT_EQ(colour_values({0.0, 0.5, 2.0}, 0.5),
            (std::vector<Rgb>{viridis(0), viridis(1), viridis(1)}));
  EXPECT_THROW(colour_values({1.0}, 0.0), std::invalid_argument);
}

// A square of two triangles facing the camera fills the usable area; a vertex-coloured
// square shows its corner colours near the corners (interpolation).
TEST(RenderMesh, SquareFillsTheViewAndInterpolatesColours) {
  Eigen::MatrixXd V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  Eigen::MatrixXi F(2, 3);
  F << 0, 1, 2, 0, 2, 3;
  const std::vector<Rgb> colours = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 255}};
  RenderOptions o;
  o.width = 50;
  o.height = 50;
  o.margin = 5;
  const Image im = render_mesh(V, F, colours, o);
  EXPECT_EQ(count_not(im, o.background), 40 * 40) << "the square covers the 40×40 interior";
  // Facing the camera: shade 1. Bottom-left pixel ≈ vertex 0 (red), bottom-right ≈ green,
  // top-right ≈ blue (y grows downwards in the image, upwards in the mesh).
  const Rgb bl = pixel(im, 5, 44), br = pixel(im, 44, 44), tr = pixel(im, 44, 5);
  EXPECT_GT(bl[0], 230);
  EXPECT_LT(bl[1], 25);
  EXPECT_GT(br[1], 230);
  EXPECT_LT(br[0], 25);
  EXPECT_GT(tr[2], 230);
}

// Two unit squares, one at z = 0 (red) and one at z = 1 (blue) shifted right by half: from +Z the
// blue one is in front where they overlap, whatever the face order. From +X (azimuth 90) both
// are seen edge-on.
TEST(RenderMesh, NearestSurfaceWinsWhateverTheOrder) {
  Eigen::MatrixXd V(8, 3);
  V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,  //
      0.5, 0, 1, 1.5, 0, 1, 1.5, 1, 1, 0.5, 1, 1;
  Eigen::MatrixXi F(4, 3), G(4, 3);
  F << 0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7;
  G << 4, 5, 6, 4, 6, 7, 0, 1, 2, 0, 2, 3;
  std::vector<Rgb> colours(8, Rgb{200, 0, 0});
  for (int v = 4; v < 8; ++v) colours[v] = {0, 0, 200};
  RenderOptions o;
  o.width = 60;
  o.height = 40;
  o.margin = 0;
  for (const Eigen::MatrixXi& faces : {F, G}) {
    const Image im = render_mesh(V, faces, colours, o);
    // x in [0, 1.5] → 60 px wide → 40 px per unit: overlap is x ∈ [0.5, 1] → pixels 20..39.
    EXPECT_EQ(pixel(im, 30, 20), (Rgb{0, 0, 200}));
    EXPECT_EQ(pixel(im, 10, 20), (Rgb{200, 0, 0}));
    EXPECT_EQ(pixel(im, 50, 20), (Rgb{0, 0, 200}));
  }
  // From +X the squares are edge-on; a facing-ratio of 0 still draws them at shade 0.35 when
  // a pixel centre falls on them, but mostly nothing: far fewer pixels than from the front.
  o.azimuth_degrees = 90;
  EXPECT_LT(count_not(render_mesh(V, F, colours, o), o.background), 60 * 40 / 4);
  EXPECT_THROW(render_mesh(V, F, std::vector<Rgb>(3), o), std::invalid_argument);
  Eigen::MatrixXi bad = F;
  bad(0, 0) = 8;
  EXPECT_THROW(render_mesh(V, bad, colours, o), std::invalid_argument);
}

TEST(Compose, SizesAndPlacement) {
  const Image a(10, 20, {1, 1, 1}), b(5, 30, {2, 2, 2}), bar(40, 4, {3, 3, 3});
  const Image row = compose_row({a, b}, 3, &bar);
  EXPECT_EQ(row.width, 40);
  EXPECT_EQ(row.height, 30 + 3 + 4);
  EXPECT_EQ(pixel(row, 0, 0), (Rgb{1, 1, 1}));
  EXPECT_EQ(pixel(row, 13, 29), (Rgb{2, 2, 2}));
  EXPECT_EQ(pixel(row, 11, 0), (Rgb{255, 255, 255}));  // the gap
  EXPECT_EQ(pixel(row, 0, 33), (Rgb{3, 3, 3}));
  const Image col = compose_column({a, b}, 2);
  EXPECT_EQ(col.width, 10);
  EXPECT_EQ(col.height, 52);
  EXPECT_EQ(pixel(col, 4, 22), (Rgb{2, 2, 2}));
  EXPECT_EQ(pixel(col, 7, 22), (Rgb{255, 255, 255}));
  const Image cb = colour_bar(100, 10, 0.05, 2);
  EXPECT_EQ(cb.width, 100);
  EXPECT_EQ(pixel(cb, 0, 0), viridis(0));
  EXPECT_EQ(pixel(cb, 99, 9), viridis(1));
}

TEST(Quantile, RankOfTheSortedValuesAndEmpty) {
  const std::vector<double> v = {5, 1, 4, 2, 3, 100, 6, 7, 8, 9, 10};  // 11 values, one outlier
  EXPECT_EQ(quantile(v, 0.0), 1);
  EXPECT_EQ(quantile(v, 0.5), 6);    // rank 5 of 0..10
  EXPECT_EQ(quantile(v, 0.95), 10);  // rank ⌊9.5⌋ = 9: the outlier does not set it
  EXPECT_EQ(quantile(v, 1.0), 100);
  EXPECT_EQ(quantile({}, 0.99), 0);
}

TEST(Ply, HeaderRowsAndValues) {
  testing::TempDir dir;
  Eigen::MatrixXd V(3, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0.25;
  Eigen::MatrixXi F(1, 3);
  F << 0, 1, 2;
  const std::vector<double> values = {0.0, 0.5, 1.5};
  write_coloured_ply(dir / "m.ply", V, F, colour_values(values, 1.0), "l1_error", values, "run x");
  std::ifstream in(dir / "m.ply");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  EXPECT_EQ(text.rfind("ply\nformat ascii 1.0\ncomment run x\nelement vertex 3\n", 0), 0u) << text;
  EXPECT_NE(text.find("property float l1_error\nelement face 1\n"), std::string::npos);
  EXPECT_NE(text.find("end_header\n0 0 0 68 1 84 0\n"), std::string::npos) << text;
  EXPECT_NE(text.find("0 1 0.25 253 231 37 1.5\n3 0 1 2\n"), std::string::npos) << text;
  EXPECT_THROW(write_coloured_ply(dir / "n.ply", V, F, {}, "x", values), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "n.ply"));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::report

#pragma once
/// \file
/// Small raster figures for generated reports (dataset cards, result tables): an RGB image, a
/// PNG writer and a bar histogram with numeric axis labels. PNG compression and checksums are
/// zlib's (deflate, crc32); the chunk framing follows the PNG specification (ISO/IEC 15948):
/// signature, IHDR (8-bit RGB, no interlace), one IDAT of filter-0 scanlines, IEND. Text is
/// limited to digits and a few symbols in a built-in 3×5 pixel font, so axis ticks are labelled
/// while titles and axis names belong in the caption of the document that shows the figure.

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace skinlab::report {

using Rgb = std::array<std::uint8_t, 3>;

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;  ///< row-major RGB, top row first

  Image(int w, int h, Rgb background = {255, 255, 255});
  void set(int x, int y, Rgb c);                          ///< ignores pixels outside the image
  void fill_rect(int x0, int y0, int x1, int y1, Rgb c);  ///< inclusive corners, clipped
  /// Copies `image` with its top-left corner at (x0, y0); pixels outside this image are dropped.
  void paste(const Image& image, int x0, int y0);
  /// Draws `text` (digits, '.', '-', '+', 'k', 'M', '%', ' ') with its top-left corner at
  /// (x, y), each font pixel `scale`×`scale`. Other characters throw std::invalid_argument.
  void text(int x, int y, const std::string& text, int scale, Rgb c);
  static int text_width(const std::string& text, int scale);
};

/// The 1, 2 or 5 × 10^k closest at or above range / bins: an axis step, or with bins = 1 a
/// scale maximum with short labels.
double nice_width(double range, int bins);

/// Encodes `image` as PNG bytes.
std::string encode_png(const Image& image);
/// Writes `image` as a PNG file atomically (core/atomic_file.hpp). Throws IoError.
void write_png(const std::filesystem::path& file, const Image& image);

struct HistogramOptions {
  int width = 640, height = 320;
  double bin_width = 0;  ///< 0: a "nice" width (1, 2 or 5 × 10^k) giving about `bins` bins
  int bins = 16;
  Rgb bar = {70, 110, 170};
};

/// Bar histogram of `values` over bins [lo + i·w, lo + (i+1)·w) with lo a multiple of w at or
/// below the minimum; y ticks are counts, x ticks bin edges. Requires at least one value.
Image histogram(const std::vector<double>& values, const HistogramOptions& options = {});

/// One curve of a line plot: points (x[i], y[i]) joined in order; non-finite y values break
/// the line (e.g. epochs without a validation loss).
struct Series {
  std::vector<double> x, y;
  Rgb colour = {70, 110, 170};
};

struct LinePlotOptions {
  int width = 640, height = 320;
};

/// Line plot of every series on shared axes from the data's ranges (y from the smallest to the
/// largest finite value, padded 5 %); y ticks and x ticks at "nice" steps. Requires at least
/// one finite point.
Image line_plot(const std::vector<Series>& series, const LinePlotOptions& options = {});

}  // namespace skinlab::report

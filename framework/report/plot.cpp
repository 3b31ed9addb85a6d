#include "framework/report/plot.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "framework/core/atomic_file.hpp"
#include "framework/core/error.hpp"

namespace skinlab::report {

namespace {

/// 3×5 glyphs, one row per string, '#' = ink.
const std::array<const char*, 5>* glyph(char c) {
  static const std::array<const char*, 5> digits[10] = {
      {"###", "#.#", "#.#", "#.#", "###"}, {".#.", "##.", ".#.", ".#.", "###"},
      {"###", "..#", "###", "#..", "###"}, {"###", "..#", "###", "..#", "###"},
      {"#.#", "#.#", "###", "..#", "..#"}, {"###", "#..", "###", "..#", "###"},
      {"###", "#..", "###", "#.#", "###"}, {"###", "..#", "..#", "..#", "..#"},
      {"###", "#.#", "###", "#.#", "###"}, {"###", "#.#", "###", "..#", "###"}};
  static const std::array<const char*, 5> dot = {"...", "...", "...", "...", ".#."};
  static const std::array<const char*, 5> minus = {"...", "...", "###", "...", "..."};
  static const std::array<const char*, 5> plus = {"...", ".#.", "###", ".#.", "..."};
  static const std::array<const char*, 5> k = {"#..", "#.#", "##.", "#.#", "#.#"};
  static const std::array<const char*, 5> m = {"#.#", "###", "###", "#.#", "#.#"};
  static const std::array<const char*, 5> percent = {"#.#", "..#", ".#.", "#..", "#.#"};
  static const std::array<const char*, 5> space = {"...", "...", "...", "...", "..."};
  if (c >= '0' && c <= '9') return &digits[c - '0'];
  switch (c) {
    case '.':
      return &dot;
    case '-':
      return &minus;
    case '+':
      return &plus;
    case 'k':
      return &k;
    case 'M':
      return &m;
    case '%':
      return &percent;
    case ' ':
      return &space;
    default:
      return nullptr;
  }
}

void put_u32(std::string& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8)
    out.push_back(static_cast<char>((v >> shift) & 0xff));
}

void chunk(std::string& out, const char* type, const std::string& data) {
  put_u32(out, static_cast<std::uint32_t>(data.size()));
  const std::string body = std::string(type, 4) + data;
  out += body;
  put_u32(out, static_cast<std::uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(body.data()),
                                                static_cast<uInt>(body.size()))));
}

std::string label(double v) {
  if (std::abs(v) >= 10000 && std::fmod(v, 1000) == 0)
    return std::to_string(static_cast<long long>(v / 1000)) + "k";
  if (v == std::floor(v)) return std::to_string(static_cast<long long>(v));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

double nice_width(double range, int bins) {
  const double raw = std::max(range, 1e-12) / std::max(bins, 1);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= raw) return m * p;
  }
  return 10 * p;
}

Image::Image(int w, int h, Rgb background) : width(w), height(h) {
  if (w <= 0 || h <= 0) throw std::invalid_argument("Image: size must be positive");
  pixels.resize(static_cast<std::size_t>(w) * h * 3);
  for (std::size_t i = 0; i < pixels.size(); i += 3) {
    std::copy(background.begin(), background.end(),
              pixels.begin() + static_cast<std::ptrdiff_t>(i));
  }
}

void Image::set(int x, int y, Rgb c) {
  if (x < 0 || y < 0 || x >= width || y >= height) return;
  std::copy(c.begin(), c.end(), pixels.begin() + (static_cast<std::ptrdiff_t>(y) * width + x) * 3);
}

void Image::paste(const Image& image, int x0, int y0) {
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::size_t i = 3 * (static_cast<std::size_t>(y) * image.width + x);
      set(x0 + x, y0 + y, {image.pixels[i], image.pixels[i + 1], image.pixels[i + 2]});
    }
  }
}

void Image::fill_rect(int x0, int y0, int x1, int y1, Rgb c) {
  for (int y = std::max(0, std::min(y0, y1)); y <= std::min(height - 1, std::max(y0, y1)); ++y) {
    for (int x = std::max(0, std::min(x0, x1)); x <= std::min(width - 1, std::max(x0, x1)); ++x) {
      set(x, y, c);
    }
  }
}

int Image::text_width(const std::string& text, int scale) {
  return text.empty() ? 0 : static_cast<int>(text.size()) * 4 * scale - scale;
}

void Image::text(int x, int y, const std::string& s, int scale, Rgb c) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto* g = glyph(s[i]);
    if (!g) throw std::invalid_argument(std::string("Image::text: no glyph for '") + s[i] + "'");
    for (int row = 0; row < 5; ++row) {
      for (int col = 0; col < 3; ++col) {
        if ((*g)[static_cast<std::size_t>(row)][col] != '#') continue;
        const int px = x + (static_cast<int>(i) * 4 + col) * scale, py = y + row * scale;
        fill_rect(px, py, px + scale - 1, py + scale - 1, c);
      }
    }
  }
}

std::string encode_png(const Image& image) {
  std::string raw;
  raw.reserve(static_cast<std::size_t>(image.height) * (1 + image.width * 3));
  for (int y = 0; y < image.height; ++y) {
    raw.push_back('\0');  // filter type 0 (none)
    raw.append(reinterpret_cast<const char*>(image.pixels.data()) +
                   static_cast<std::ptrdiff_t>(y) * image.width * 3,
               static_cast<std::size_t>(image.width) * 3);
  }
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string compressed(size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(compressed.data()), &size,
                reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()),
                Z_BEST_COMPRESSION) != Z_OK) {
    throw Error("encode_png: zlib compress2 failed");
  }
  compressed.resize(size);
  std::string png = "\x89PNG\r\n\x1a\n";
  std::string ihdr;
  put_u32(ihdr, static_cast<std::uint32_t>(image.width));
  put_u32(ihdr, static_cast<std::uint32_t>(image.height));
  ihdr += std::string("\x08\x02\x00\x00\x00", 5);  // 8-bit, RGB, deflate, filter 0, no interlace
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", compressed);
  chunk(png, "IEND", "");
  return png;
}

void write_png(const std::filesystem::path& file, const Image& image) {
  write_file_atomic(file, encode_png(image));
}

Image histogram(const std::vector<double>& values, const HistogramOptions& o) {
  if (values.empty()) throw std::invalid_argument("histogram: no values");
  const auto [min_it, max_it] = std::minmax_element(values.begin(), values.end());
  const double w = o.bin_width > 0 ? o.bin_width : nice_width(*max_it - *min_it, o.bins);
  const double lo = std::floor(*min_it / w) * w;
  const int bins = std::max(1, static_cast<int>(std::floor((*max_it - lo) / w)) + 1);
  std::vector<int> count(static_cast<std::size_t>(bins), 0);
  for (double v : values) {
    count[static_cast<std::size_t>(
        std::clamp(static_cast<int>(std::floor((v - lo) / w)), 0, bins - 1))]++;
  }
  const int top = *std::max_element(count.begin(), count.end());

  const int scale = 2, glyph_h = 5 * scale;
  const Rgb ink = {40, 40, 40}, grid = {225, 225, 225};
  Image img(o.width, o.height);
  const int left = 12 + Image::text_width(std::to_string(top), scale), right = o.width - 12;
  const int bottom = o.height - 14 - glyph_h, top_y = 12;
  // y ticks: about 5 integer steps.
  const int step = std::max(1, static_cast<int>(nice_width(top, 5)));
  auto y_of = [&](double c) {
    return bottom - static_cast<int>(std::lround(c / std::max(top, 1) * (bottom - top_y)));
  };
  for (int c = 0; c <= top; c += step) {
    img.fill_rect(left, y_of(c), right, y_of(c), grid);
    const std::string t = std::to_string(c);
    img.text(left - 6 - Image::text_width(t, scale), y_of(c) - glyph_h / 2, t, scale, ink);
  }
  const double bar_w = static_cast<double>(right - left) / bins;
  for (int b = 0; b < bins; ++b) {
    const int x0 = left + static_cast<int>(std::lround(b * bar_w)) + 1;
    const int x1 = left + static_cast<int>(std::lround((b + 1) * bar_w)) - 1;
    if (count[static_cast<std::size_t>(b)] > 0)
      img.fill_rect(x0, y_of(count[static_cast<std::size_t>(b)]), x1, bottom, o.bar);
  }
  img.fill_rect(left, bottom, right, bottom, ink);
  img.fill_rect(left, top_y, left, bottom, ink);
  // x ticks at bin edges, skipping labels that would overlap.
  int last_end = -1000;
  for (int b = 0; b <= bins; ++b) {
    const int x = left + static_cast<int>(std::lround(b * bar_w));
    img.fill_rect(x, bottom, x, bottom + 3, ink);
    const std::string t = label(lo + b * w);
    const int tw = Image::text_width(t, scale);
    if (x - tw / 2 > last_end + 6 && x + tw / 2 < o.width) {
      img.text(x - tw / 2, bottom + 6, t, scale, ink);
      last_end = x + tw / 2;
    }
  }
  return img;
}

namespace {

void draw_line(Image& img, int x0, int y0, int x1, int y1, Rgb c) {
  const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
  const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
  for (int err = dx + dy;;) {  // Bresenham, 2 px thick
    img.fill_rect(x0, y0, x0 + 1, y0 + 1, c);
    if (x0 == x1 && y0 == y1) break;
    const int e2 = 2 * err;
    if (e2 >= dy) err += dy, x0 += sx;
    if (e2 <= dx) err += dx, y0 += sy;
  }
}

}  // namespace

Image line_plot(const std::vector<Series>& series, const LinePlotOptions& o) {
  double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
  for (const auto& s : series) {
    if (s.x.size() != s.y.size()) throw std::invalid_argument("line_plot: x and y differ in size");
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.y[i]) || !std::isfinite(s.x[i])) continue;
      x_lo = std::min(x_lo, s.x[i]), x_hi = std::max(x_hi, s.x[i]);
      y_lo = std::min(y_lo, s.y[i]), y_hi = std::max(y_hi, s.y[i]);
    }
  }
  if (!std::isfinite(x_lo)) throw std::invalid_argument("line_plot: no finite point");
  const double pad = std::max(y_hi - y_lo, std::abs(y_hi) * 1e-3 + 1e-12) * 0.05;
  const double y_step = nice_width(y_hi - y_lo + 2 * pad, 5);
  y_lo = std::floor((y_lo - pad) / y_step) * y_step;
  y_hi = std::ceil((y_hi + pad) / y_step) * y_step;
  if (x_hi == x_lo) x_hi = x_lo + 1;
  const double x_step = nice_width(x_hi - x_lo, 8);

  const int scale = 2, glyph_h = 5 * scale;
  const Rgb ink = {40, 40, 40}, grid = {225, 225, 225};
  Image img(o.width, o.height);
  int label_w = 0;
  for (double v = y_lo; v <= y_hi + y_step / 2; v += y_step)
    label_w = std::max(label_w, Image::text_width(label(std::round(v / y_step) * y_step), scale));
  const int left = 12 + label_w, right = o.width - 16;
  const int bottom = o.height - 14 - glyph_h, top = 12;
  auto px = [&](double x) {
    return left + static_cast<int>(std::lround((x - x_lo) / (x_hi - x_lo) * (right - left)));
  };
  auto py = [&](double y) {
    return bottom - static_cast<int>(std::lround((y - y_lo) / (y_hi - y_lo) * (bottom - top)));
  };
  for (double v = y_lo; v <= y_hi + y_step / 2; v += y_step) {
    const double tick = std::round(v / y_step) * y_step;
    img.fill_rect(left, py(tick), right, py(tick), grid);
    const std::string t = label(tick);
    img.text(left - 6 - Image::text_width(t, scale), py(tick) - glyph_h / 2, t, scale, ink);
  }
  for (double v = std::ceil(x_lo / x_step) * x_step; v <= x_hi + x_step / 2; v += x_step) {
    const int x = px(v);
    img.fill_rect(x, bottom, x, bottom + 3, ink);
    const std::string t = label(v);
    const int tw = Image::text_width(t, scale);
    img.text(std::min(x - tw / 2, o.width - tw - 1), bottom + 6, t, scale, ink);
  }
  img.fill_rect(left, bottom, right, bottom, ink);
  img.fill_rect(left, top, left, bottom, ink);
  for (const auto& s : series) {
    bool have = false;
    int last_x = 0, last_y = 0;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.y[i]) || !std::isfinite(s.x[i])) {
        have = false;
        continue;
      }
      const int x = px(s.x[i]), y = py(s.y[i]);
      if (have)
        draw_line(img, last_x, last_y, x, y, s.colour);
      else
        img.fill_rect(x - 1, y - 1, x + 1, y + 1, s.colour);
      have = true, last_x = x, last_y = y;
    }
  }
  return img;
}

}  // namespace skinlab::report

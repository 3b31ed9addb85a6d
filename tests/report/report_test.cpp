// PNG writer, histogram and dataset card (framework/report/).

#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>

#include "../data/data_fixtures.hpp"
#include "../test_util.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/report/dataset_card.hpp"
#include "framework/report/plot.hpp"

namespace skinlab::report {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

std::uint32_t u32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i)
    v = (v << 8) | static_cast<std::uint8_t>(s[at + static_cast<std::size_t>(i)]);
  return v;
}

TEST(Png, ChunksCarryValidCrcsAndTheScanlinesInflateToThePixels) {
  Image img(5, 3, {10, 20, 30});
  img.set(4, 2, {255, 0, 0});
  const std::string png = encode_png(img);
  ASSERT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  std::size_t at = 8;
  std::string idat;
  std::vector<std::string> types;
  while (at < png.size()) {
    const std::uint32_t len = u32(png, at);
    const std::string type = png.substr(at + 4, 4);
    const std::string body = png.substr(at + 4, 4 + len);
    EXPECT_EQ(u32(png, at + 8 + len),
              crc32(0, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size())))
        << type;
    if (type == "IHDR") {
      EXPECT_EQ(u32(png, at + 8), 5u);
      EXPECT_EQ(u32(png, at + 12), 3u);
    }
    if (type == "IDAT") idat += png.substr(at + 8, len);
    types.push_back(type);
    at += 12 + len;
  }
  EXPECT_EQ(types, (std::vector<std::string>{"IHDR", "IDAT", "IEND"}));
  std::string raw(3 * (1 + 5 * 3), '\0');
  uLongf size = static_cast<uLongf>(raw.size());
  ASSERT_EQ(
      uncompress(reinterpret_cast<Bytef*>(raw.data()), &size,
                 reinterpret_cast<const Bytef*>(idat.data()), static_cast<uLong>(idat.size())),
      Z_OK);
  ASSERT_EQ(size, raw.size());
  EXPECT_EQ(raw[0], '\0');                                             // filter byte
  EXPECT_EQ(static_cast<std::uint8_t>(raw[1]), 10);                    // first pixel
  EXPECT_EQ(static_cast<std::uint8_t>(raw[2 * 16 + 1 + 4 * 3]), 255);  // the red pixel
}

TEST(Histogram, BarHeightsFollowTheCounts) {
  HistogramOptions o;
  o.bin_width = 10;
  // Bins [0,10): 1 value, [10,20): 3 values, [20,30): 2 values.
  const Image img = histogram({1, 11, 12, 19, 25, 29}, o);
  auto bar_top = [&](int x) {
    for (int y = 0; y < img.height; ++y) {
      const auto* p = &img.pixels[(static_cast<std::size_t>(y) * img.width + x) * 3];
      if (p[0] == o.bar[0] && p[1] == o.bar[1] && p[2] == o.bar[2]) return y;
    }
    return img.height;
  };
  // Bars are a third of the plot wide each; sample the middle of each.
  const int left = 12 + Image::text_width("3", 2), right = img.width - 12;
  const double w = (right - left) / 3.0;
  const int h1 = bar_top(left + static_cast<int>(0.5 * w));
  const int h2 = bar_top(left + static_cast<int>(1.5 * w));
  const int h3 = bar_top(left + static_cast<int>(2.5 * w));
  EXPECT_LT(h2, h3);
  EXPECT_LT(h3, h1);
  EXPECT_THROW(histogram({}), std::invalid_argument);
  Image text(20, 10);
  EXPECT_THROW(text.text(0, 0, "x", 1, {0, 0, 0}), std::invalid_argument);
}

TEST(LinePlot, CurvesFollowTheirValuesAndGapsBreakThem) {
  // A falling series and a rising one, each over x = 0..10; the second has a gap at x = 5.
  Series down{{}, {}, {200, 0, 0}}, up{{}, {}, {0, 0, 200}};
  for (int i = 0; i <= 10; ++i) {
    down.x.push_back(i), down.y.push_back(10 - i);
    up.x.push_back(i), up.y.push_back(i == 5 ? NAN : i);
  }
  const Image img = line_plot({down, up});
  auto rows_of = [&](Rgb c, int x) {  // topmost row of colour c in column x, or -1
    for (int y = 0; y < img.height; ++y) {
      const auto* p = &img.pixels[(static_cast<std::size_t>(y) * img.width + x) * 3];
      if (p[0] == c[0] && p[1] == c[1] && p[2] == c[2]) return y;
    }
    return -1;
  };
  int left_x = 0;  // the first column where the falling curve appears
  while (rows_of(down.colour, left_x) < 0) ++left_x;
  const int right_x = img.width - 17;
  ASSERT_GT(rows_of(down.colour, right_x), 0);
  EXPECT_LT(rows_of(down.colour, left_x + 2), rows_of(down.colour, right_x)) << "falls";
  EXPECT_GT(rows_of(up.colour, left_x + 2), rows_of(up.colour, right_x)) << "rises";
  // No blue between x = 4 and x = 6 (the gap), blue again right after x = 6.
  const double per_unit = (right_x - left_x) / 10.0;
  EXPECT_EQ(rows_of(up.colour, left_x + static_cast<int>(5 * per_unit)), -1);
  EXPECT_GT(rows_of(up.colour, left_x + static_cast<int>(6.5 * per_unit)), 0);
  EXPECT_THROW(line_plot({Series{{1}, {NAN}}}), std::invalid_argument);
  EXPECT_THROW(line_plot({Series{{1, 2}, {1}}}), std::invalid_argument);
}

TEST(DatasetCard, ReportsCountsSplitsExclusionsAndLicencesWithoutAugmentedCopies) {
  data::Dataset d;
  d.characters = {testing::tiny_character("a"), testing::tiny_character("b"),
                  testing::tiny_character("c")};
  d.characters[1].group = "a";
  d.characters[2].source = "other";
  d.characters[2].skeleton = "bird";
  d.characters[2].licence = "GPL-2+";
  // b: four clips of 8 frames besides its own 2-frame one; c: no bind pose.
  for (int k = 0; k < 4; ++k) {
    data::AnimationData clip = d.characters[1].animations.front();
    clip.name = "long" + std::to_string(k);
    clip.num_frames = 8;
    clip.frames.assign(static_cast<std::size_t>(8 * 3 * 12), 0.5f);
    d.characters[1].animations.push_back(clip);
  }
  d.characters[2].bind.clear();
  // An augmented training copy of a (data/augment.hpp): in no table, counted once.
  d.characters.push_back(testing::tiny_character("a~aug0"));
  d.characters[3].augmented_from = "a";
  d.characters[3].group = "a";
  d.splits["random"] = {{0, 1, 3}, {}, {2}};
  d.excluded = {{"test", "dir/x.fbx", "x: rigid-only weights | one joint"}};
  testing::TempDir dir;
  DatasetCardOptions options;
  options.command = "skinlab dataset-card d.h5";
  write_dataset_card(d, "results/d.h5", dir / "README.md", options);
  const std::string md = read_file(dir / "README.md");
  for (const std::string part :
       {"# Dataset card: d", "`skinlab dataset-card d.h5`", "| other | 1 | 1 | 1 | 0 |",
        "| test | 2 | 1 | 1 | 1 |", "| **all** | **3** | **2** | **2** | **1** |",
        "| random | 0 / 0 / 1 | 2 / 0 / 0 | 2 / 0 / 1 |" /* other, test, all: train/val/test */,
        "rigid-only weights \\| one joint", "| other | GPL-2+ | 1 | skinlab tests |",
        "| 2 | c | other | bird | c | 5 → 4 |", "![", "card/bones.png",
        // bind poses and clips: with bind, with clips, with ≥ 4 of ≥ 8 frames, clips, frames
        "## Bind poses and clips", "| other | 0 | 1 | 0 | 1 | 2 |", "| test | 2 | 2 | 1 | 6 | 36 |",
        "| **all** | **2** | **3** | **1** | **7** | **38** |"}) {
    EXPECT_NE(md.find(part), std::string::npos) << part << "\n" << md;
  }
  EXPECT_NE(md.find("also holds 1 augmented copies"), std::string::npos) << md;
  EXPECT_EQ(md.find("a~aug0"), std::string::npos) << md;
  for (const char* png : {"vertices.png", "source_vertices.png", "joints.png", "bones.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "card" / png)) << png;
  }
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::report

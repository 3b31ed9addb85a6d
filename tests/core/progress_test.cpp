#include "framework/core/progress.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

TEST(Progress, FormatsCountRateAndEta) {
  EXPECT_EQ(Progress::format("train", 25, 100, 10.0), "train 25/100 (25.0%) 2.50/s ETA 0:00:30");
  EXPECT_EQ(Progress::format("train", 100, 100, 10.0), "train 100/100 (100.0%) 10.00/s ETA 0:00:00");
  EXPECT_EQ(Progress::format("scan", 7, 0, 2.0), "scan 7 3.50/s");
  EXPECT_EQ(Progress::format("x", 0, 10, 0.0), "x 0/10 (0.0%) 0.00/s ETA --:--:--");
  EXPECT_EQ(Progress::format("long", 1, 3601, 1.0), "long 1/3601 (0.0%) 1.00/s ETA 1:00:00");
}

TEST(Progress, ReportsPeriodicallyAndOnceAtTheEnd) {
  std::vector<std::pair<std::string, bool>> lines;
  {
    Progress progress("items", 3, 0.0, [&](const std::string& line, bool final) {
      lines.emplace_back(line, final);
    });
    progress.tick();
    progress.tick(2);
    progress.finish();
    progress.finish();  // idempotent
  }  // destructor after finish() reports nothing more
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].first.rfind("items 1/3", 0), 0u);
  EXPECT_FALSE(lines[1].second);
  EXPECT_EQ(lines[2].first.rfind("items 3/3 (100.0%)", 0), 0u);
  EXPECT_TRUE(lines[2].second);
}

TEST(Progress, LongIntervalOnlyReportsTheEnd) {
  std::vector<std::string> lines;
  {
    Progress progress("items", 1000, 3600.0,
                      [&](const std::string& line, bool) { lines.push_back(line); });
    for (int i = 0; i < 1000; ++i) progress.tick();
  }
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].rfind("items 1000/1000", 0), 0u);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

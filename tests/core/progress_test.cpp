#include "framework/core/progress.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
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
  // the tick that reaches the total does not report: the final line is the only 3/3 line
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].first.rfind("items 1/3", 0), 0u);
  EXPECT_FALSE(lines[0].second);
  EXPECT_EQ(lines[1].first.rfind("items 3/3 (100.0%)", 0), 0u);
  EXPECT_TRUE(lines[1].second);
}

TEST(Progress, ALogLineOnTheTerminalMovesTheBarBelowIt) {
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  auto log = [&] { std::fputs("[info] a log line\n", out); };
  {
    Progress progress("items", 2, 0.0, Progress::terminal_sink(out));
    progress.tick();
    Progress::around_log_line(log);  // while the bar is drawn
    progress.tick();
  }
  Progress::around_log_line(log);  // after the final line: written as is
  std::rewind(out);
  std::string text;
  for (int ch; (ch = std::fgetc(out)) != EOF;) text += static_cast<char>(ch);
  std::fclose(out);
  // drawn, cleared for the log line, redrawn under it, then replaced by the final line
  const auto first = text.find("\r\033[Kitems 1/2 (50.0%)");
  const auto cleared = text.find("\r\033[K[info] a log line\nitems 1/2 (50.0%)");
  const auto last = text.find("\r\033[Kitems 2/2 (100.0%)");
  EXPECT_EQ(first, 0u) << text;
  EXPECT_NE(cleared, std::string::npos) << text;
  EXPECT_NE(last, std::string::npos) << text;
  EXPECT_LT(cleared, last) << text;
  EXPECT_EQ(text.substr(text.size() - 19), "\n[info] a log line\n") << text;
  EXPECT_EQ(text.find("items 2/2", last + 5), std::string::npos) << "the last line twice: " << text;
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

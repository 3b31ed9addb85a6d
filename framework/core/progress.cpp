#include "framework/core/progress.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <mutex>

#include <fmt/core.h>

namespace skinlab {

namespace {

std::string format_duration(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  return fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60);
}

/// The bar drawn last on the terminal, while it is not finished (log lines move it down).
struct TerminalLine {
  std::mutex mutex;
  std::string text;
  std::FILE* out = nullptr;  ///< where it is drawn; null when no bar is drawn
};

TerminalLine& terminal_line() {
  static TerminalLine line;
  return line;
}

Progress::Sink log_sink() {
  return [](const std::string& line, bool) { spdlog::info("{}", line); };
}

}  // namespace

Progress::Sink Progress::terminal_sink(std::FILE* out) {
  return [out](const std::string& line, bool final) {
    TerminalLine& bar = terminal_line();
    const std::lock_guard<std::mutex> lock(bar.mutex);
    std::fprintf(out, "\r\033[K%s%s", line.c_str(), final ? "\n" : "");
    std::fflush(out);
    bar.text = line;
    bar.out = final ? nullptr : out;
  };
}

void Progress::around_log_line(const std::function<void()>& write) {
  TerminalLine& bar = terminal_line();
  const std::lock_guard<std::mutex> lock(bar.mutex);
  if (bar.out != nullptr) {
    std::fputs("\r\033[K", bar.out);
    std::fflush(bar.out);
  }
  write();
  if (bar.out != nullptr) {
    std::fputs(bar.text.c_str(), bar.out);
    std::fflush(bar.out);
  }
}

Progress::Progress(std::string label, std::size_t total, double interval_seconds)
    : Progress(std::move(label), total, ::isatty(STDERR_FILENO) ? 0.1 : interval_seconds,
               ::isatty(STDERR_FILENO) ? terminal_sink(stderr) : log_sink()) {}

Progress::Progress(std::string label, std::size_t total, double interval_seconds, Sink sink)
    : label_(std::move(label)),
      total_(total),
      interval_(interval_seconds),
      sink_(std::move(sink)),
      start_(Clock::now()),
      last_(start_) {}

Progress::~Progress() {
  try {
    finish();
  } catch (...) {  // a failing sink must not terminate the program from a destructor
  }
}

void Progress::tick(std::size_t n) {
  done_ += n;
  if (total_ > 0 && done_ >= total_) return;  // finish() reports the last line, once
  const auto now = Clock::now();
  if (std::chrono::duration<double>(now - last_).count() >= interval_) {
    last_ = now;
    report(false);
  }
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  report(true);
}

void Progress::report(bool final) {
  const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
  sink_(format(label_, done_, total_, elapsed), final);
}

std::string Progress::format(const std::string& label, std::size_t done, std::size_t total,
                             double elapsed_seconds) {
  const double rate = elapsed_seconds > 0 ? static_cast<double>(done) / elapsed_seconds : 0.0;
  if (total == 0) return fmt::format("{} {} {:.2f}/s", label, done, rate);
  const double percent = 100.0 * static_cast<double>(done) / static_cast<double>(total);
  std::string eta = "--:--:--";
  if (done >= total) {
    eta = format_duration(0);
  } else if (rate > 0) {
    eta = format_duration(static_cast<double>(total - done) / rate);
  }
  return fmt::format("{} {}/{} ({:.1f}%) {:.2f}/s ETA {}", label, done, total, percent, rate, eta);
}

}  // namespace skinlab

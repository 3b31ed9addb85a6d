#pragma once
/// \file
/// Progress reporting for long loops: a self-updating line with count, rate and ETA on a
/// terminal, plain periodic log lines otherwise (CI logs, `log.txt`).

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <string>

namespace skinlab {

class Progress {
 public:
  using Clock = std::chrono::steady_clock;
  /// Receives a formatted line; `final` is true for the last one.
  using Sink = std::function<void(const std::string& line, bool final)>;

  /// Reports `total` steps of `label`. On a terminal (stderr is a tty) the line is redrawn at
  /// most 10 times a second; otherwise a log line is written every `interval_seconds`.
  Progress(std::string label, std::size_t total, double interval_seconds = 10.0);
  /// Reports to `sink` every `interval_seconds` (tests, custom front ends).
  Progress(std::string label, std::size_t total, double interval_seconds, Sink sink);
  ~Progress();

  /// Advances by `n` steps. Reaching the total reports nothing: finish() reports the last line.
  void tick(std::size_t n = 1);
  /// Reports the final line (also done by the destructor if not called).
  void finish();

  /// The sink that draws the bar on a terminal `out` (stderr when it is a tty): the line is
  /// redrawn in place, and the final one ends with a newline.
  static Sink terminal_sink(std::FILE* out);
  /// Runs `write` (which writes whole lines, e.g. a log sink) so that they do not land on a bar
  /// being drawn by terminal_sink: the bar is cleared first and redrawn under them. logging.cpp's
  /// console sink writes through it.
  static void around_log_line(const std::function<void()>& write);

  /// "label 12/100 (12.0%) 3.40/s ETA 0:00:26"; without a total, "label 12 3.40/s".
  static std::string format(const std::string& label, std::size_t done, std::size_t total,
                            double elapsed_seconds);

 private:
  void report(bool final);
  std::string label_;
  std::size_t total_;
  std::size_t done_ = 0;
  double interval_;
  Sink sink_;
  Clock::time_point start_;
  Clock::time_point last_;
  bool finished_ = false;
};

}  // namespace skinlab

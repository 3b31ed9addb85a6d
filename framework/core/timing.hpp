#pragma once
/// \file
/// Wall-clock seconds for the stage timings that commands, distances and benchmarks report.

#include <chrono>

namespace skinlab {

/// Seconds from `start` to now on the steady clock.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace skinlab

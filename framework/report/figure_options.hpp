#pragma once
/// \file
/// The options of `skinlab figure`, shared by every task's figures (framework/task/task.hpp):
/// each task reads the ones it draws with.

#include <filesystem>
#include <string>
#include <vector>

namespace skinlab::report {

struct FigureOptions {
  std::vector<std::string> runs;        ///< evaluated run directories, one column each
  std::string part = "test";            ///< evaluated part (predictions/<part>.h5)
  std::vector<std::string> characters;  ///< empty: the first `count` of the first run's part
  int count = 3;
  double l1_max = 1.0;        ///< skinning: top of the L1 colour scale (L1 is in [0, 2])
  int poses = 3;              ///< corrective: evaluation poses per character, evenly spaced
  double error_max_cm = 0;    ///< corrective: top of the error scale in cm; 0: per figure, its 99th percentile
  std::filesystem::path out;  ///< output directory (created)
};

}  // namespace skinlab::report

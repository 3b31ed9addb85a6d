// Whole-file fuzzing of every file format skinlab reads back (label `long`): dataset files,
// predictions files, parameters.h5, training checkpoints and bundled models
// (tests/fuzz/file_targets.hpp). Any byte may change: superblock, object headers, B-trees,
// attributes, every dataset, zip headers and pickles. Each mutant is read in a forked child
// with a per-input time limit (tests/fuzz/fork_fuzz.hpp); it must be accepted or rejected with
// skinlab::Error, and a time-out, a crash or another exception fails the test and saves the
// input. Budget SKINLAB_FUZZ_SECONDS per target (default 60), seed SKINLAB_FUZZ_SEED (default
// 1), per-input limit SKINLAB_FUZZ_INPUT_SECONDS (default 5).
//
//   ctest --test-dir build -L long -R FileFuzz

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "tests/fuzz/file_targets.hpp"
#include "tests/fuzz/fork_fuzz.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {

class FileFuzz : public ::testing::TestWithParam<std::string> {};

TEST_P(FileFuzz, EveryMutantIsAcceptedOrRejectedWithinTheTimeLimit) {
  torch::set_num_threads(1);  // no thread pool to inherit across fork()
  for (const auto& target : fuzz::file_targets()) {
    if (target.name != GetParam()) continue;
    testing::TempDir dir;
    const auto seeds = target.seeds(dir.path());
    for (std::size_t i = 0; i < seeds.size(); ++i) {  // every seed itself is read
      const std::filesystem::path file = dir / ("seed" + std::to_string(i) + target.extension);
      write_file_atomic(file, seeds[i]);
      ASSERT_NO_THROW(target.parse(file)) << target.name << " seed " << i;
    }
    const std::filesystem::path file = dir / ("fuzzed" + target.extension);
    const fuzz::ForkTally t = fuzz::fuzz_file(target.name, seeds, file, [&] { target.parse(file); });
    EXPECT_GT(t.tried, 100);
    EXPECT_GT(t.counts[static_cast<int>(fuzz::Outcome::kRejected)], 0);
    return;
  }
  FAIL() << "no target " << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Targets, FileFuzz,
                         ::testing::Values("dataset", "predictions", "parameters", "checkpoint",
                                           "model"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace skinlab

// Seeded random-mutation fuzzing of the game-file readers of datasets/ (label `long`), one test
// per reader (reader_targets.hpp: PMD, PSA, 0 A.D. skeleton XML, IQM, ZYM, pk3/zip, OGRE mesh and
// skeleton, C4Group), with the harness of fuzz_harness.hpp: every mutant must be accepted or
// rejected with skinlab::Error, for SKINLAB_FUZZ_SECONDS (default 60) per reader from
// SKINLAB_FUZZ_SEED (default 1).
//
//   ctest --test-dir build -L long -R FuzzReaders
//   ctest --test-dir build -L long -R 'FuzzReaders.*/zym$' --output-on-failure

#include <gtest/gtest.h>

#include "tests/fuzz/reader_targets.hpp"

namespace skinlab::fuzz {
namespace {
namespace SKINLAB_UNITY_ID {

class FuzzReaders : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzReaders, AcceptsOrRejectsEveryMutant) {
  for (const ReaderTarget& target : reader_targets()) {
    if (target.name != GetParam()) continue;
    const Tally t = target.binary ? run(target.name, target.seeds(), mutate_binary, target.parse)
                                  : run(target.name, target.seeds(), mutate, target.parse);
    EXPECT_GT(t.tried, 100);
    EXPECT_GT(t.rejected, 0);
    EXPECT_EQ(t.failed, 0);
    return;
  }
  FAIL() << "no reader target " << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Readers, FuzzReaders,
                         ::testing::Values("pmd", "psa", "skeleton_xml", "iqm", "zym", "pk3",
                                           "ogre_mesh", "ogre_skeleton", "c4group"),
                         [](const auto& info) { return info.param; });

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::fuzz

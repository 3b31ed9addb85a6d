// The inputs whole-file fuzzing found (tests/fuzz/h5_fuzz_test.cpp), replayed in the fast
// suite: every file under tests/data/fuzz_regressions/files/<target>/ is read by its target's reader
// (tests/fuzz/file_targets.hpp) in a forked child with a time limit, and must be accepted or
// rejected with skinlab::Error, never hang, crash or throw anything else. The files named
// *vlen* are hand-made (tests/data/fuzz_regressions/files/make_global_heap_cases.py).

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <set>

#include "tests/fuzz/file_targets.hpp"
#include "tests/fuzz/fork_fuzz.hpp"

namespace skinlab {
namespace {

namespace fs = std::filesystem;

TEST(FileFuzzRegressions, EverySavedInputIsAcceptedOrRejected) {
  torch::set_num_threads(1);
  const fs::path root = fs::path(SKINLAB_SOURCE_DIR) / "tests/data/fuzz_regressions/files";
  std::set<std::string> known;
  for (const auto& target : fuzz::file_targets()) known.insert(target.name);
  int replayed = 0;
  for (const auto& dir : fs::directory_iterator(root)) {
    if (!dir.is_directory()) continue;
    EXPECT_TRUE(known.count(dir.path().filename().string())) << "no target " << dir.path();
  }
  for (const auto& target : fuzz::file_targets()) {
    if (!fs::exists(root / target.name)) continue;
    for (const auto& entry : fs::directory_iterator(root / target.name)) {
      if (entry.path().extension() != target.extension) continue;
      SCOPED_TRACE(entry.path().string());
      // A generous limit: a reproducer reads in milliseconds; 30 s is a hang even on a busy CI.
      const fuzz::Result r = fuzz::run_forked([&] { target.parse(entry.path()); }, 30);
      EXPECT_TRUE(r.outcome == fuzz::Outcome::kAccepted || r.outcome == fuzz::Outcome::kRejected)
          << fuzz::name_of(r.outcome) << ": " << r.detail;
      if (entry.path().filename().string().find("vlen") != std::string::npos) {
        // Hand-made (make_global_heap_cases.py): variable-length strings over a damaged global
        // heap, on which libhdf5 crashes; refused by version or string type before any read.
        EXPECT_EQ(r.outcome, fuzz::Outcome::kRejected) << r.detail;
      }
      if (r.outcome == fuzz::Outcome::kRejected) {
        // Rejections name the file (skinlab's error convention).
        EXPECT_NE(r.detail.find(entry.path().filename().string()), std::string::npos) << r.detail;
      }
      ++replayed;
    }
  }
  std::cout << replayed << " saved inputs replayed\n";
  EXPECT_GT(replayed, 0);
}

}  // namespace
}  // namespace skinlab

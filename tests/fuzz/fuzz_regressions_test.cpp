// The inputs the reader fuzzing found bugs with (tests/data/fuzz_regressions/readers/<target>/, one
// directory per reader target of reader_targets.hpp), fed to their reader in the fast suite:
// each must be accepted or rejected with skinlab::Error, never crash, hang or throw anything
// else. docs/development.md ("Fuzzing") lists what each one found.

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "tests/fuzz/reader_targets.hpp"

namespace skinlab::fuzz {
namespace {
namespace SKINLAB_UNITY_ID {

TEST(FuzzRegressions, EveryKeptInputIsAcceptedOrRejectedWithAnError) {
  const fs::path root = fs::path(SKINLAB_SOURCE_DIR) / "tests/data/fuzz_regressions/readers";
  std::map<std::string, ReaderTarget> targets;
  for (ReaderTarget& t : reader_targets()) targets.emplace(t.name, std::move(t));
  std::set<fs::path> dirs;
  for (const auto& d : fs::directory_iterator(root)) dirs.insert(d.path());
  ASSERT_FALSE(dirs.empty());
  int inputs = 0;
  for (const fs::path& dir : dirs) {
    ASSERT_TRUE(fs::is_directory(dir)) << dir;
    const auto target = targets.find(dir.filename().string());
    ASSERT_NE(target, targets.end()) << "no reader target named " << dir.filename();
    std::set<fs::path> files;
    for (const auto& f : fs::directory_iterator(dir)) files.insert(f.path());
    for (const fs::path& file : files) {
      ++inputs;
      try {
        target->second.parse(read_bytes(file), file);
      } catch (const Error&) {
        // rejected: fine
      } catch (const std::exception& e) {
        ADD_FAILURE() << file << " threw " << typeid(e).name() << " instead of skinlab::Error: "
                      << e.what();
      }
    }
  }
  EXPECT_GT(inputs, 0);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::fuzz

#include "framework/core/atomic_file.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>

#include "framework/core/error.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::TempDir;

std::size_t count_files(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}

TEST(AtomicFile, WritesAndReplaces) {
  TempDir dir;
  const auto target = dir / "out.txt";
  write_file_atomic(target, "first");
  EXPECT_EQ(read_file(target), "first");
  write_file_atomic(target, "second, longer");
  EXPECT_EQ(read_file(target), "second, longer");
  EXPECT_EQ(count_files(dir.path()), 1u);  // no temporary left behind
}

TEST(AtomicFile, AbandonedWriteKeepsTheOldFile) {
  TempDir dir;
  const auto target = dir / "out.txt";
  write_file_atomic(target, "good");
  try {
    AtomicPath out(target);
    std::ofstream(out.temp()) << "half of a new ver";
    throw std::runtime_error("crash while writing");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(read_file(target), "good");
  EXPECT_EQ(count_files(dir.path()), 1u);  // the temporary was removed
}

TEST(AtomicFile, KilledWriterLeavesTheOldFile) {
  TempDir dir;
  const auto target = dir / "out.txt";
  write_file_atomic(target, "good");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    AtomicPath out(target);
    std::ofstream file(out.temp());
    file << "partial";
    file.flush();
    ::kill(::getpid(), SIGKILL);  // dies mid-write: no destructor, no commit
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(read_file(target), "good");
}

TEST(AtomicFile, CommitWithoutWritingIsAnError) {
  TempDir dir;
  AtomicPath out(dir / "never.txt");
  testing::expect_error<IoError>([&] { out.commit(); }, {"never.txt", "nothing was written"});
  EXPECT_FALSE(std::filesystem::exists(dir / "never.txt"));
}

TEST(AtomicFile, MissingDirectoryNamesThePath) {
  TempDir dir;
  testing::expect_error<IoError>([&] { write_file_atomic(dir / "no/such/dir/x.txt", "x"); },
                                 {"no/such/dir/x.txt"});
  testing::expect_error<IoError>([&] { read_file(dir / "absent.txt"); },
                                 {"absent.txt", "cannot open"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

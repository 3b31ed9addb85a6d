// install_interrupt_cleanup: an interrupted process removes its AtomicPath temporary files and
// its lock files, says so in one line and ends by the signal; an ignored signal stays ignored.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <vector>
#include <string>

#include "framework/core/atomic_file.hpp"
#include "framework/core/interrupt.hpp"
#include "framework/core/output_lock.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using testing::TempDir;

/// A child process that installs the handlers (after ignoring SIGINT when `ignore_sigint`),
/// takes `<dir>/out.h5.lock`, writes half of `<dir>/out.h5` and of `<dir>/notes.txt` into their
/// temporary files, reports ready and waits to be signalled. Its stderr goes to
/// `<dir>/stderr.txt`. Returns its pid once it is ready.
pid_t start_writer(const TempDir& dir, bool ignore_sigint) {
  int ready[2];
  if (::pipe(ready) != 0) return -1;
  const pid_t child = ::fork();
  if (child == 0) {
    const int err = ::open((dir / "stderr.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(err, STDERR_FILENO);
    if (ignore_sigint) ::signal(SIGINT, SIG_IGN);
    install_interrupt_cleanup("writer");
    const OutputLock lock(lock_file_of(dir / "out.h5"), (dir / "out.h5").string(), {"writer"});
    AtomicPath data(dir / "out.h5"), notes(dir / "notes.txt");
    std::ofstream(data.temp()) << "half of a dataset";
    std::ofstream(notes.temp()) << "half of the notes";
    const char byte = 1;
    if (::write(ready[1], &byte, 1) != 1) std::_Exit(2);
    for (;;) ::pause();
  }
  char byte = 0;
  const bool started = child > 0 && ::read(ready[0], &byte, 1) == 1;
  ::close(ready[0]);
  ::close(ready[1]);
  return started ? child : -1;
}

/// The names in `dir` except stderr.txt.
std::vector<std::string> left_in(const TempDir& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    if (entry.path().filename() != "stderr.txt") names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(Interrupt, SigintRemovesTemporaryAndLockFilesAndEndsByTheSignal) {
  TempDir dir;
  const pid_t child = start_writer(dir, false);
  ASSERT_GT(child, 0);
  EXPECT_EQ(left_in(dir).size(), 3u) << "the lock file and two temporary files";
  ::kill(child, SIGINT);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), SIGINT);
  EXPECT_EQ(left_in(dir), std::vector<std::string>{});
  EXPECT_EQ(read_file(dir / "stderr.txt"),
            "writer: interrupted by SIGINT; temporary files removed, no output half-written\n");
}

TEST(Interrupt, AnIgnoredSigintStaysIgnoredAndSigtermStillCleansUp) {
  TempDir dir;
  const pid_t child = start_writer(dir, true);
  ASSERT_GT(child, 0);
  ::kill(child, SIGINT);
  ::usleep(100000);
  int status = 0;
  EXPECT_EQ(::waitpid(child, &status, WNOHANG), 0) << "still running after SIGINT";
  ::kill(child, SIGTERM);
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_EQ(left_in(dir), std::vector<std::string>{});
}

TEST(Interrupt, CommittedAndDestroyedPathsAreNoLongerTracked) {
  // More AtomicPaths than there are slots over a process's life, then a lock and one more
  // temporary file: every commit and destruction freed its slot, so the last two are still
  // tracked and removed by an interruption.
  TempDir dir;
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::dup2(::open((dir / "stderr.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), STDERR_FILENO);
    install_interrupt_cleanup("writer");
    for (std::size_t i = 0; i <= kInterruptSlots; ++i) {
      write_file_atomic(dir / "kept.txt", std::to_string(i));
      const AtomicPath abandoned(dir / "other.txt");
      std::ofstream(abandoned.temp()) << i;
    }
    const OutputLock lock(lock_file_of(dir / "out.h5"), (dir / "out.h5").string(), {"writer"});
    AtomicPath last(dir / "out.h5");
    std::ofstream(last.temp()) << "half";
    const char byte = 1;
    if (::write(ready[1], &byte, 1) != 1) std::_Exit(2);
    for (;;) ::pause();
  }
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  ::close(ready[0]);
  ::close(ready[1]);
  EXPECT_EQ(left_in(dir).size(), 3u) << "kept.txt, the lock and a temporary file";
  ::kill(child, SIGTERM);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM);
  EXPECT_EQ(left_in(dir), std::vector<std::string>{"kept.txt"});
  EXPECT_EQ(read_file(dir / "kept.txt"), std::to_string(kInterruptSlots));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

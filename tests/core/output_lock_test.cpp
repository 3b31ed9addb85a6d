// OutputLock: a second writer fails at once naming the first; a lock whose owner ended
// without releasing it (killed) is taken over; releasing removes the lock file.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "framework/core/atomic_file.hpp"
#include "framework/core/error.hpp"
#include "framework/core/output_lock.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using testing::TempDir;

const std::vector<std::string> kCommand = {"/usr/bin/skinlab", "prepare", "configs/x y.yaml"};

TEST(OutputLock, SecondWriterFailsNamingTheFirstAndReleaseRemovesTheFile) {
  TempDir dir;
  const fs::path out = dir / "data.h5";
  const fs::path lock_file = lock_file_of(out);
  EXPECT_EQ(lock_file, dir / "data.h5.lock");
  {
    const OutputLock lock(lock_file, out.string(), kCommand);
    const std::string record = read_file(lock_file);
    EXPECT_NE(record.find("pid: " + std::to_string(::getpid()) + "\n"), std::string::npos) << record;
    EXPECT_NE(record.find("command: skinlab prepare 'configs/x y.yaml'\n"), std::string::npos) << record;
    // flock locks belong to an open file: a second open of the same file conflicts even in
    // this process, as another process's does.
    testing::expect_error<Error>(
        [&] { OutputLock second(lock_file, out.string(), {"skinlab", "prepare"}); },
        {out.string() + " is being written by pid " + std::to_string(::getpid()) + " on ",
         "(skinlab prepare 'configs/x y.yaml', started ", " UTC); wait for it to finish or stop it",
         "(lock " + lock_file.string() + ")"});
  }
  EXPECT_FALSE(fs::exists(lock_file));
  const OutputLock again(lock_file, out.string(), kCommand);
  EXPECT_TRUE(fs::exists(lock_file));
}

TEST(OutputLock, ALockLeftByAKilledOwnerBlocksNobody) {
  TempDir dir;
  const fs::path out = dir / "run";
  const fs::path lock_file = dir / "train.lock";
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const OutputLock lock(lock_file, out.string(), {"skinlab", "train", "--resume", "run"});
    const char byte = 1;
    if (::write(ready[1], &byte, 1) != 1) std::_Exit(2);
    for (;;) ::pause();
  }
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  testing::expect_error<Error>([&] { OutputLock second(lock_file, out.string(), kCommand); },
                               {"is being written by pid " + std::to_string(child) + " on ",
                                "(skinlab train --resume run, started "});
  // SIGKILL: no destructor, no handler; the file stays with the dead owner's record.
  ::kill(child, SIGKILL);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(fs::exists(lock_file));
  const OutputLock lock(lock_file, out.string(), kCommand);
  EXPECT_NE(read_file(lock_file).find("pid: " + std::to_string(::getpid()) + "\n"), std::string::npos);
  ::close(ready[0]);
  ::close(ready[1]);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

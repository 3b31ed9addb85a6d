#pragma once
/// \file
/// One writer per output. `skinlab prepare` holds `<output>.lock` next to the dataset file it
/// writes; `skinlab train` (new or `--resume`) holds `train.lock` inside its run directory, and
/// `skinlab eval` `eval_<part>.lock` there, so a second process pointed at the same output fails
/// at once, naming the first, instead of interleaving its writes with it.
///
/// The lock is flock(2) on the lock file, which the kernel releases when the owner ends however
/// it ends: a lock file left by a crashed or killed owner (SIGKILL) blocks nobody, and the next
/// process takes it over with a warning. The file holds the owner's pid, host, start time and
/// command line, for the message of a process that finds it taken. Released on destruction
/// (the file is removed), and removed by the interrupt handlers (core/interrupt.hpp).
///
/// flock works between processes on one machine and, on Linux, on NFS (as a POSIX lock); on a
/// file system without locks construction fails with an IoError naming the file.

#include <filesystem>
#include <string>
#include <vector>

namespace skinlab {

class OutputLock {
 public:
  /// Takes `lock_file` (created if missing) before writing `output` (what the message names).
  /// Throws Error "<output> is being written by pid <pid> on <host> (<command>, started <time>);
  /// wait for it to finish or stop it (lock <lock_file>)" when another process holds it, and
  /// IoError when the file cannot be created or locked. `command` is the owner's command line.
  OutputLock(std::filesystem::path lock_file, std::string output,
             const std::vector<std::string>& command);
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;
  /// Removes the lock file and releases the lock.
  ~OutputLock();

  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
  int fd_ = -1;
};

/// `<output>.lock`, the lock file of a single output file (`skinlab prepare`).
std::filesystem::path lock_file_of(const std::filesystem::path& output);
/// `<run_dir>/train.lock`, held while a process trains the run.
std::filesystem::path train_lock_of(const std::filesystem::path& run_dir);
/// `<run_dir>/eval_<part>.lock`, held while a process writes the run's evaluation of `part`.
std::filesystem::path eval_lock_of(const std::filesystem::path& run_dir, const std::string& part);

}  // namespace skinlab

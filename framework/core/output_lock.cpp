#include "framework/core/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <map>
#include <thread>

#include "framework/core/error.hpp"
#include "framework/core/interrupt.hpp"

namespace skinlab {

namespace fs = std::filesystem;

namespace output_lock_detail {

std::string now_utc() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  ::gmtime_r(&now, &utc);
  std::array<char, 32> text{};
  std::strftime(text.data(), text.size(), "%Y-%m-%d %H:%M:%S UTC", &utc);
  return text.data();
}

std::string host_name() {
  std::array<char, 256> name{};
  if (::gethostname(name.data(), name.size() - 1) != 0) return "?";
  return name.data();
}

/// The command line as one string: the program's file name, then the arguments, quoted when
/// they hold a space.
std::string command_text(const std::vector<std::string>& command) {
  std::string out;
  for (std::size_t i = 0; i < command.size(); ++i) {
    const std::string a = i == 0 ? fs::path(command[i]).filename().string() : command[i];
    if (!out.empty()) out += ' ';
    out += a.find_first_of(" \t'\"") == std::string::npos || a.empty() ? a : "'" + a + "'";
  }
  return out;
}

/// The whole content of the open file `fd`.
std::string read_all(int fd) {
  std::string out;
  std::array<char, 4096> buffer{};
  off_t offset = 0;
  for (;;) {
    const ssize_t n = ::pread(fd, buffer.data(), buffer.size(), offset);
    if (n <= 0) break;
    out.append(buffer.data(), static_cast<std::size_t>(n));
    offset += n;
  }
  return out;
}

/// The `key: value` lines of a lock file.
std::map<std::string, std::string> fields(const std::string& text) {
  std::map<std::string, std::string> out;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    const std::size_t colon = line.find(": ");
    if (colon != std::string::npos) out[line.substr(0, colon)] = line.substr(colon + 2);
    start = end + 1;
  }
  return out;
}

/// "pid 1234 on host (skinlab prepare ..., started ...)" from a lock file's text.
std::string owner_text(const std::string& text) {
  auto f = fields(text);
  if (f["pid"].empty()) return "another process (it has not recorded itself yet)";
  return fmt::format("pid {} on {} ({}, started {})", f["pid"], f["host"], f["command"], f["started"]);
}

bool same_file(int fd, const fs::path& path) {
  struct stat open_file {}, named {};
  if (::fstat(fd, &open_file) != 0 || ::stat(path.c_str(), &named) != 0) return false;
  return open_file.st_dev == named.st_dev && open_file.st_ino == named.st_ino;
}

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
  throw IoError(path.string() + ": " + what + ": " + std::strerror(errno));
}

}  // namespace output_lock_detail

namespace lockd = output_lock_detail;

fs::path lock_file_of(const fs::path& output) {
  fs::path out = output;
  out += ".lock";
  return out;
}

fs::path train_lock_of(const fs::path& run_dir) { return run_dir / "train.lock"; }

fs::path eval_lock_of(const fs::path& run_dir, const std::string& part) {
  return run_dir / ("eval_" + part + ".lock");
}

OutputLock::OutputLock(fs::path lock_file, std::string output,
                       const std::vector<std::string>& command)
    : file_(std::move(lock_file)) {
  // A releasing owner removes the file while holding the lock; a process that opened the old
  // file and then gets its lock finds the name no longer refers to it and tries again.
  for (int attempt = 0; attempt < 100 && fd_ < 0; ++attempt) {
    const int fd = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) lockd::fail(file_, "cannot create the lock file");
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      if (errno != EWOULDBLOCK) {
        ::close(fd);
        lockd::fail(file_, "cannot lock");
      }
      // The owner writes its record right after locking: give it a moment.
      std::string owner = lockd::read_all(fd);
      for (int wait = 0; wait < 20 && lockd::fields(owner)["pid"].empty(); ++wait) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        owner = lockd::read_all(fd);
      }
      ::close(fd);
      throw Error(fmt::format("{} is being written by {}; wait for it to finish or stop it (lock {})",
                              output, lockd::owner_text(owner), file_.string()));
    }
    if (!lockd::same_file(fd, file_)) {
      ::close(fd);
      continue;
    }
    fd_ = fd;
  }
  if (fd_ < 0) throw IoError(file_.string() + ": cannot take the lock (its file keeps changing)");
  const std::string previous = lockd::read_all(fd_);
  if (!lockd::fields(previous)["pid"].empty()) {
    spdlog::warn("{}: taking over the lock of {}, which no longer holds it (ended without "
                 "releasing it)", file_.string(), lockd::owner_text(previous));
  }
  const std::string record =
      fmt::format("pid: {}\nhost: {}\nstarted: {}\ncommand: {}\noutput: {}\n", ::getpid(),
                  lockd::host_name(), lockd::now_utc(), lockd::command_text(command), output);
  if (::ftruncate(fd_, 0) != 0 ||
      ::pwrite(fd_, record.data(), record.size(), 0) != static_cast<ssize_t>(record.size())) {
    const int error = errno;
    ::close(fd_);
    errno = error;
    lockd::fail(file_, "cannot write the lock file");
  }
  remove_on_interrupt(file_);
}

OutputLock::~OutputLock() {
  keep_on_interrupt(file_);
  if (lockd::same_file(fd_, file_)) ::unlink(file_.c_str());  // still holding the lock
  ::close(fd_);
}

}  // namespace skinlab

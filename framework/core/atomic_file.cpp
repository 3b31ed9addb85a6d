#include "framework/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "framework/core/error.hpp"
#include "framework/core/interrupt.hpp"

namespace skinlab {

namespace fs = std::filesystem;

namespace {

std::atomic<unsigned> temp_counter{0};

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
  throw IoError(path.string() + ": " + what + ": " + std::strerror(errno));
}

void fsync_path(const fs::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) fail(path, "cannot open for sync");
  const int rc = ::fsync(fd);
  ::close(fd);
  // Some file systems refuse fsync on directories; data is already renamed, so only a file
  // sync failure is an error.
  if (rc != 0 && !(flags & O_DIRECTORY)) fail(path, "fsync failed");
}

}  // namespace

AtomicPath::AtomicPath(fs::path target) : target_(std::move(target)) {
  const fs::path dir = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
  temp_ = dir / ("." + target_.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                 std::to_string(temp_counter++));
  remove_on_interrupt(temp_);
}

AtomicPath::~AtomicPath() {
  if (!committed_) {
    std::error_code ignored;
    fs::remove(temp_, ignored);
  }
  if (!committed_) keep_on_interrupt(temp_);
}

void AtomicPath::commit() {
  if (committed_) return;
  if (!fs::exists(temp_)) {
    throw IoError(target_.string() + ": nothing was written to the temporary file " +
                  temp_.string());
  }
  fsync_path(temp_, O_RDONLY);
  if (::rename(temp_.c_str(), target_.c_str()) != 0) fail(target_, "cannot rename into place");
  committed_ = true;
  keep_on_interrupt(temp_);
  const fs::path dir = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
  fsync_path(dir, O_RDONLY | O_DIRECTORY);
}

void write_file_atomic(const fs::path& target, std::string_view contents) {
  AtomicPath out(target);
  {
    std::ofstream file(out.temp(), std::ios::binary | std::ios::trunc);
    if (!file) fail(target, "cannot create temporary file " + out.temp().string());
    file.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    file.flush();
    if (!file) fail(target, "write failed");
  }
  out.commit();
}

void write_directory_atomic(const fs::path& target,
                            const std::function<void(const fs::path& staging)>& write) {
  fs::path staging = target;
  staging += ".partial";
  fs::remove_all(staging);
  fs::create_directories(staging);
  try {
    write(staging);
    fs::rename(staging, target);  // POSIX rename replaces an empty directory
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(staging, ignored);
    throw;
  }
}

std::string read_file(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) fail(path, "cannot open for reading");
  std::ostringstream buffer;
  buffer << file.rdbuf();
  return buffer.str();
}

}  // namespace skinlab

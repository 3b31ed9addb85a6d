#include "framework/core/launch.hpp"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <thread>

#include "framework/core/error.hpp"

namespace skinlab {

namespace {

std::string describe(int status) {
  if (WIFEXITED(status)) return fmt::format("exited with status {}", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    return fmt::format("was killed by signal {} ({})", WTERMSIG(status), strsignal(WTERMSIG(status)));
  }
  return fmt::format("ended with wait status {}", status);
}

bool failed(int status) { return !WIFEXITED(status) || WEXITSTATUS(status) != 0; }

}  // namespace

int threads_per_worker(int requested, int nproc) {
  if (requested > 0) return requested;
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<int>(std::max(1u, cores / static_cast<unsigned>(std::max(nproc, 1))));
}

int free_local_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw IoError(std::string("launch: socket(): ") + std::strerror(errno));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  socklen_t length = sizeof(address);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    const std::string error = std::strerror(errno);
    ::close(fd);
    throw IoError("launch: no free port on 127.0.0.1: " + error);
  }
  ::close(fd);
  return ntohs(address.sin_port);
}

void launch_local(const LaunchOptions& options) {
  if (options.nproc < 1) throw Error(fmt::format("launch: --nproc must be ≥ 1, got {}", options.nproc));
  const int port = free_local_port();
  std::vector<std::string> argv_text{"/proc/self/exe"};
  argv_text.insert(argv_text.end(), options.args.begin(), options.args.end());
  std::vector<pid_t> pids;
  const pid_t parent = ::getpid();
  for (int rank = 0; rank < options.nproc; ++rank) {
    std::vector<std::string> env = options.environment;
    env.push_back(fmt::format("RANK={}", rank));
    env.push_back(fmt::format("LOCAL_RANK={}", rank));
    env.push_back(fmt::format("WORLD_SIZE={}", options.nproc));
    env.push_back("MASTER_ADDR=127.0.0.1");
    env.push_back(fmt::format("MASTER_PORT={}", port));
    const pid_t pid = ::fork();
    if (pid < 0) {
      for (pid_t p : pids) ::kill(p, SIGKILL);
      throw IoError(std::string("launch: fork(): ") + std::strerror(errno));
    }
    if (pid == 0) {
      // A launcher that is interrupted or killed takes its workers with it (SIGTERM: they
      // remove their temporary files, core/interrupt.hpp) instead of leaving them writing
      // outputs whose lock the launcher no longer holds.
      ::prctl(PR_SET_PDEATHSIG, SIGTERM);
      if (::getppid() != parent) std::_Exit(1);
      for (const std::string& e : env) ::putenv(const_cast<char*>(e.c_str()));
      std::vector<char*> argv;
      for (const std::string& a : argv_text) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv("/proc/self/exe", argv.data());
      std::fprintf(stderr, "launch: exec of rank %d failed: %s\n", rank, std::strerror(errno));
      std::_Exit(127);
    }
    pids.push_back(pid);
  }
  spdlog::info("launched {} worker processes (127.0.0.1:{})", options.nproc, port);

  // Reap every worker; after the first failure stop the others (SIGTERM, then SIGKILL after
  // `grace`). Every failure is reported, those the launcher caused marked as such.
  const std::size_t n = pids.size();
  std::vector<int> status(n, 0);
  std::vector<bool> running(n, true), stopped(n, false);
  std::size_t left = n;
  bool stopping = false;
  std::size_t first = n;  // the first worker that failed
  auto deadline = std::chrono::steady_clock::time_point::max();
  while (left > 0) {
    int s = 0;
    const pid_t pid = ::waitpid(-1, &s, stopping ? WNOHANG : 0);
    if (pid < 0 && errno == EINTR) continue;
    if (pid < 0) break;
    if (pid == 0) {  // stopping, nobody exited yet
      if (std::chrono::steady_clock::now() >= deadline) {
        for (std::size_t r = 0; r < n; ++r) {
          if (running[r]) ::kill(pids[r], SIGKILL);
        }
        deadline = std::chrono::steady_clock::time_point::max();
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    std::size_t r = 0;
    while (r < n && pids[r] != pid) ++r;
    if (r == n) continue;
    running[r] = false;
    status[r] = s;
    --left;
    if (failed(s) && !stopping) {
      stopping = true;
      first = r;
      spdlog::error("worker rank {} {}; stopping the other workers", r, describe(s));
      for (std::size_t o = 0; o < n; ++o) {
        if (running[o]) {
          stopped[o] = true;
          ::kill(pids[o], SIGTERM);
        }
      }
      deadline = std::chrono::steady_clock::now() + options.grace;
    }
  }
  if (first == n) return;
  std::string others;
  for (std::size_t r = 0; r < n; ++r) {
    if (r == first || !failed(status[r])) continue;
    others += fmt::format("{}rank {} {}{}", others.empty() ? "" : ", ", r, describe(status[r]),
                          stopped[r] ? " (stopped by the launcher)" : "");
  }
  throw Error(fmt::format("worker rank {} of {} (pid {}) {}; the run was stopped{}", first, n,
                          pids[first], describe(status[first]),
                          others.empty() ? "" : " (then " + others + ")"));
}

}  // namespace skinlab

#pragma once
// Whole-file fuzzing with a per-input time limit, shared by tests/fuzz/h5_fuzz_test.cpp (label
// long) and tests/fuzz/h5_regressions_test.cpp (label fast). Each input is parsed in a forked
// child under alarm(): the child exits 0 (accepted), 1 (rejected with skinlab::Error) or 2
// (another exception, its type and message sent back through a pipe); a signal death is a crash
// and SIGALRM a time-out. So a hang or a crash of one input is a finding, not the end of the run.

#include <H5Cpp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <random>
#include <string>
#include <typeinfo>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/core/error.hpp"
#include "tests/fuzz/fuzz_harness.hpp"

namespace skinlab::fuzz {

// budget_seconds() and seed() (SKINLAB_FUZZ_SECONDS, SKINLAB_FUZZ_SEED) are the harness's.

/// The per-input time limit in seconds (SKINLAB_FUZZ_INPUT_SECONDS, default 5).
inline unsigned input_seconds() {
  const char* env = std::getenv("SKINLAB_FUZZ_INPUT_SECONDS");
  return env != nullptr ? static_cast<unsigned>(std::atoi(env)) : 5u;
}

enum class Outcome { kAccepted, kRejected, kOtherException, kCrashed, kTimedOut };

inline const char* name_of(Outcome o) {
  switch (o) {
    case Outcome::kAccepted: return "accepted";
    case Outcome::kRejected: return "rejected";
    case Outcome::kOtherException: return "other-exception";
    case Outcome::kCrashed: return "crash";
    case Outcome::kTimedOut: return "timeout";
  }
  return "?";
}

struct Result {
  Outcome outcome;
  std::string detail;  ///< the exception's message, or the signal
};

/// Runs `parse` in a forked child killed by SIGALRM after `seconds`.
inline Result run_forked(const std::function<void()>& parse, unsigned seconds) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  std::cout.flush();
  std::cerr.flush();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    close(fds[0]);
    signal(SIGALRM, SIG_DFL);
    alarm(seconds);
    int code = 0;
    std::string message;
    try {
      parse();
    } catch (const Error& e) {
      code = 1;
      message = e.what();
    } catch (const std::exception& e) {
      code = 2;
      message = std::string(typeid(e).name()) + ": " + e.what();
    } catch (const H5::Exception& e) {
      code = 2;
      message = "H5::Exception from " + e.getFuncName() + ": " + e.getDetailMsg();
    } catch (...) {
      code = 2;
      message = "a non-std exception";
    }
    message = message.substr(0, 4000);
    std::size_t written = 0;
    while (written < message.size()) {
      const ssize_t n = write(fds[1], message.data() + written, message.size() - written);
      if (n <= 0) break;
      written += static_cast<std::size_t>(n);
    }
    _exit(code);  // no destructors, atexit handlers or gtest teardown in the child
  }
  close(fds[1]);
  std::string detail;
  char buffer[4096];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) detail.append(buffer, n);
  close(fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    return {sig == SIGALRM ? Outcome::kTimedOut : Outcome::kCrashed,
            std::string("signal ") + strsignal(sig)};
  }
  switch (WEXITSTATUS(status)) {
    case 0: return {Outcome::kAccepted, detail};
    case 1: return {Outcome::kRejected, detail};
    default: return {Outcome::kOtherException, detail};
  }
}

/// One in-place or resizing edit of a binary file: flip a bit, set a byte, write an
/// "interesting" 1-, 2-, 4- or 8-byte little-endian integer (0, 1, all ones, sign bits, small
/// and huge sizes) anywhere, copy a run of bytes over another place, or (rarely) insert, delete
/// or truncate.
inline void mutate_bytes(std::string& s, std::mt19937_64& rng) {
  if (s.empty()) return;
  auto pick = [&](std::size_t n) {
    return n == 0 ? std::size_t{0} : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng);
  };
  static const std::uint64_t interesting[] = {0,          1,          2,          0x7f,
                                              0x80,       0xff,       0x100,      0x7fff,
                                              0x8000,     0xffff,     0x10000,    0x7fffffff,
                                              0x80000000, 0xffffffff, 0x100000000ull,
                                              0x7fffffffffffffffull, ~0ull, 16, 64, 4096};
  const std::size_t at = pick(s.size());
  switch (pick(16)) {
    case 0: case 1: case 2: case 3:
      s[at] = static_cast<char>(s[at] ^ (1u << pick(8)));
      break;
    case 4: case 5: case 6:
      s[at] = static_cast<char>(pick(256));
      break;
    case 7: case 8: case 9: case 10: {
      static const std::size_t widths[] = {1, 2, 4, 8};
      const std::size_t width = widths[pick(4)];
      std::uint64_t v = interesting[pick(sizeof interesting / sizeof interesting[0])];
      if (pick(4) == 0) v = v + pick(5) - 2;
      for (std::size_t i = 0; i < width && at + i < s.size(); ++i) {
        s[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
      }
      break;
    }
    case 11: case 12: {
      const std::size_t from = pick(s.size());
      const std::size_t n = std::min({1 + pick(32), s.size() - from, s.size() - at});
      std::memmove(s.data() + at, s.data() + from, n);
      break;
    }
    case 13:
      s.insert(at, 1 + pick(8), static_cast<char>(pick(256)));
      break;
    case 14:
      s.erase(at, std::min<std::size_t>(1 + pick(8), s.size() - at));
      break;
    default:
      if (pick(4) == 0) s.resize(at);  // truncation, rarer than the rest
      else s[at] = 0;
      break;
  }
}

/// Counts of one target's run, by outcome.
struct ForkTally {
  long tried = 0;
  long counts[5] = {0, 0, 0, 0, 0};  ///< by Outcome
  long failures() const {
    return counts[static_cast<int>(Outcome::kOtherException)] +
           counts[static_cast<int>(Outcome::kCrashed)] +
           counts[static_cast<int>(Outcome::kTimedOut)];
  }
};

/// Where findings are saved: SKINLAB_FUZZ_FINDINGS or <temp>/skinlab-fuzz-findings.
inline fs::path findings_dir() {
  const char* env = std::getenv("SKINLAB_FUZZ_FINDINGS");
  return env != nullptr ? fs::path(env) : fs::temp_directory_path() / "skinlab-fuzz-findings";
}

/// Mutates `seeds` (1–4 edits each) until the time budget is spent; each mutant is written to
/// `file` and `parse` runs on it in a forked child. Every time-out, crash or exception other
/// than skinlab::Error is a test failure, and its input is saved under
/// findings_dir()/<target>/ (to be moved to tests/data/fuzz_regressions/files/<target>/ once fixed).
inline ForkTally fuzz_file(const std::string& target, const std::vector<std::string>& seeds,
                       const fs::path& file, const std::function<void()>& parse) {
  std::mt19937_64 rng(seed());
  ForkTally t;
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + std::chrono::duration<double>(budget_seconds());
  std::vector<std::string> reported;
  while (std::chrono::steady_clock::now() < end) {
    std::string input = seeds[static_cast<std::size_t>(t.tried) % seeds.size()];
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) mutate_bytes(input, rng);
    write_file_atomic(file, input);
    ++t.tried;
    const Result r = run_forked(parse, input_seconds());
    ++t.counts[static_cast<int>(r.outcome)];
    if (r.outcome == Outcome::kAccepted || r.outcome == Outcome::kRejected) continue;
    const fs::path dir = findings_dir() / target;
    fs::create_directories(dir);
    const fs::path saved =
        dir / (std::string(name_of(r.outcome)) + "-seed" + std::to_string(seed()) + "-input" +
               std::to_string(t.tried) + file.extension().string());
    write_file_atomic(saved, input);
    if (reported.size() < 10) {
      reported.push_back(saved.string() + ": " + name_of(r.outcome) + ": " + r.detail);
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << target << ": " << t.tried << " inputs in " << seconds << " s, "
            << t.counts[0] << " accepted, " << t.counts[1] << " rejected, "
            << t.counts[2] << " other exceptions, " << t.counts[3] << " crashes, "
            << t.counts[4] << " time-outs (" << input_seconds() << " s limit)\n";
  for (const auto& line : reported) ADD_FAILURE() << target << ": " << line;
  return t;
}

}  // namespace skinlab::fuzz

#pragma once
// The seeded random-mutation fuzzing harness shared by every fuzz target (parsers_fuzz_test.cpp,
// readers_fuzz_test.cpp). A target is a set of seed inputs and a `parse` callable; every mutant
// must be accepted (parse returns) or rejected with skinlab::Error. Any other exception is a
// finding: the harness counts it, keeps the input as `<input file>.failure-N` and fails the
// test at the end. So that a crash or a hang keeps its reproducer too:
// - every mutant is written to a known file before it is parsed (`fuzz-<target>.input` in
//   SKINLAB_FUZZ_DIR, default the working directory, build/tests under ctest), whose path is
//   printed to stderr first; after a crash that file is the crashing input;
// - a watchdog thread ends the process (exit code 3) when one input takes longer than
//   SKINLAB_FUZZ_INPUT_SECONDS (default 10), naming that file;
// - the address space is capped (SKINLAB_FUZZ_MEMORY_MB, default 4096; not under
//   AddressSanitizer, which reserves terabytes of it), so an absurd allocation becomes a
//   std::bad_alloc finding instead of swapping the machine.
// Each target runs for SKINLAB_FUZZ_SECONDS (default 60) from SKINLAB_FUZZ_SEED (default 1) and
// prints how many inputs it tried, accepted and rejected.

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <typeinfo>
#include <vector>

#include "framework/core/error.hpp"

#if defined(__SANITIZE_ADDRESS__)
#define SKINLAB_FUZZ_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SKINLAB_FUZZ_ASAN 1
#endif
#endif

namespace skinlab::fuzz {

namespace fs = std::filesystem;

inline double env_number(const char* name, double fallback) {
  const char* env = std::getenv(name);
  return env != nullptr ? std::atof(env) : fallback;
}

inline double budget_seconds() { return env_number("SKINLAB_FUZZ_SECONDS", 60.0); }

inline std::uint64_t seed() {
  const char* env = std::getenv("SKINLAB_FUZZ_SEED");
  return env != nullptr ? std::strtoull(env, nullptr, 10) : 1;
}

inline std::size_t pick(std::mt19937_64& rng, std::size_t n) {
  return n == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng);
}

/// One random edit of `s`: flip a bit, set a byte, insert a token that parsers tend to
/// mishandle, delete a run, duplicate a slice or truncate.
inline void mutate(std::string& s, std::mt19937_64& rng) {
  static const std::vector<std::string> tokens = {
      " ",    "\n",     "\t",  "nan",  "-nan", "inf", "1e400", "-0", "99999999999999999999",
      "-1",   "0x10",   "#",   "root", "hier", "skin", "joints", "\r\n", std::string(1, '\0'),
      "1e-320", "\xff\xfe", "3.4028236e38"};
  switch (pick(rng, 6)) {
    case 0:
      if (!s.empty()) s[pick(rng, s.size())] ^= static_cast<char>(1u << pick(rng, 8));
      break;
    case 1:
      if (!s.empty()) s[pick(rng, s.size())] = static_cast<char>(pick(rng, 256));
      break;
    case 2:
      s.insert(pick(rng, s.size() + 1), tokens[pick(rng, tokens.size())]);
      break;
    case 3:
      if (!s.empty()) {
        const std::size_t at = pick(rng, s.size());
        s.erase(at, 1 + pick(rng, std::min<std::size_t>(16, s.size() - at)));
      }
      break;
    case 4:
      if (!s.empty()) {
        const std::size_t at = pick(rng, s.size());
        const std::string slice = s.substr(at, 1 + pick(rng, 64));
        s.insert(pick(rng, s.size() + 1), slice);
      }
      break;
    default:
      if (s.size() > 1) s.resize(pick(rng, s.size()));  // truncation
      break;
  }
}

/// An edit of a binary file: half the time one of mutate()'s, otherwise a 16- or 32-bit field
/// (at an aligned or any offset, in the first 512 bytes with probability 1/2, where headers,
/// counts and offsets live) set to a boundary value in either byte order.
inline void mutate_binary(std::string& s, std::mt19937_64& rng) {
  if (s.size() < 4 || pick(rng, 2) == 0) {
    mutate(s, rng);
    return;
  }
  static const std::uint32_t values[] = {0,          1,          2,          3,
                                         0x7f,       0x80,       0xff,       0x100,
                                         0x7fff,     0x8000,     0xffff,     0x10000,
                                         0x7fffffff, 0x80000000, 0xfffffffe, 0xffffffff,
                                         0x3f800000 /* 1.0f */,  0x7fc00000 /* NaN */,
                                         0x7f800000 /* inf */,   0x40000000};
  const bool wide = pick(rng, 2) == 0;
  const std::size_t width = wide ? 4 : 2;
  const std::size_t range = pick(rng, 2) == 0 ? std::min<std::size_t>(512, s.size()) : s.size();
  if (range < width) return;
  const std::size_t align = pick(rng, 2) == 0 ? width : 1;  // zip fields are not aligned
  const std::size_t at = pick(rng, (range - width) / align + 1) * align;
  std::uint32_t v = values[pick(rng, std::size(values))];
  if (!wide) v &= 0xffff;
  const bool big = pick(rng, 4) == 0;
  for (std::size_t i = 0; i < width; ++i) {
    const std::size_t shift = 8 * (big ? width - 1 - i : i);
    s[at + i] = static_cast<char>((v >> shift) & 0xff);
  }
}

/// Writes `bytes` to `file` (truncating it); the file is complete once this returns, so it
/// survives a crash of the process.
inline void write_bytes(const fs::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

/// The bytes of `file` (test fixtures and seeds).
inline std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  return std::string(std::istreambuf_iterator<char>(in), {});
}

struct Tally {
  long tried = 0, accepted = 0, rejected = 0, failed = 0;
};

/// Caps the address space once per process (see the file comment).
inline void limit_memory() {
#ifndef SKINLAB_FUZZ_ASAN
  static const bool done = [] {
    const double mb = env_number("SKINLAB_FUZZ_MEMORY_MB", 4096);
    if (mb > 0) {
      const rlim_t bytes = static_cast<rlim_t>(mb * 1024 * 1024);
      rlimit r{};
      getrlimit(RLIMIT_AS, &r);
      if (r.rlim_cur == RLIM_INFINITY || r.rlim_cur > bytes) {
        r.rlim_cur = bytes;
        setrlimit(RLIMIT_AS, &r);
      }
    }
    return true;
  }();
  (void)done;
#endif
}

/// Ends the process when one input runs longer than the per-input limit.
class Watchdog {
 public:
  Watchdog(std::string target, fs::path input)
      : target_(std::move(target)), input_(std::move(input)),
        limit_(env_number("SKINLAB_FUZZ_INPUT_SECONDS", 10)) {
    thread_ = std::thread([this] { run(); });
  }
  ~Watchdog() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  /// Input `n` starts now.
  void start(long n) {
    number_.store(n);
    started_.store(now_ms());
  }
  /// No input is running.
  void idle() { started_.store(0); }

 private:
  static std::int64_t now_ms() {
    return std::chrono::duration_cast<std::chrono::milliseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_for(lock, std::chrono::milliseconds(200), [this] { return stop_; })) {
      const std::int64_t started = started_.load();
      if (limit_ > 0 && started > 0 && now_ms() - started > static_cast<std::int64_t>(limit_ * 1000)) {
        std::cerr << "fuzz " << target_ << ": input " << number_.load() << " (seed " << seed()
                  << ") has run for more than " << limit_ << " s: a hang; the input is "
                  << input_.string() << std::endl;
        std::_Exit(3);
      }
    }
  }

  std::string target_;
  fs::path input_;
  double limit_;
  std::atomic<long> number_{0};
  std::atomic<std::int64_t> started_{0};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

/// The file a target's current input is written to.
inline fs::path input_file(const std::string& target) {
  const char* dir = std::getenv("SKINLAB_FUZZ_DIR");
  return fs::absolute(dir != nullptr ? fs::path(dir) : fs::current_path()) /
         ("fuzz-" + target + ".input");
}

/// Runs `parse(bytes, file)` on `input` (already written to `file`); returns true when it was
/// accepted, false when it was rejected with skinlab::Error, and throws std::string naming any
/// other exception.
template <class Parse>
bool accepts(Parse& parse, const std::string& input, const fs::path& file) {
  try {
    parse(input, file);
    return true;
  } catch (const Error&) {
    return false;
  } catch (const std::exception& e) {
    throw std::string(typeid(e).name()) + " instead of skinlab::Error: " + e.what();
  } catch (...) {
    throw std::string("an exception not derived from std::exception");
  }
}

/// Mutates `seeds` (1–4 edits of `edit` each, seed k for input k mod #seeds) until the time
/// budget is spent and calls `parse(bytes, file)` on each mutant, `file` holding the bytes.
/// Keeps up to 10 failing inputs as `<file>.failure-N` and reports each with ADD_FAILURE.
template <class Edit, class Parse>
Tally run(const std::string& target, const std::vector<std::string>& seeds, Edit edit,
          Parse parse) {
  limit_memory();
  const fs::path file = input_file(target);
  std::cerr << "fuzz " << target << ": each input is written to " << file.string()
            << " before it is parsed (after a crash it is the crashing input)" << std::endl;
  std::mt19937_64 rng(seed());
  Tally t;
  Watchdog watchdog(target, file);
  const auto end =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(budget_seconds());
  while (std::chrono::steady_clock::now() < end) {
    std::string input = seeds[static_cast<std::size_t>(t.tried) % seeds.size()];
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) edit(input, rng);
    write_bytes(file, input);
    ++t.tried;
    watchdog.start(t.tried);
    try {
      if (accepts(parse, input, file)) {
        ++t.accepted;
      } else {
        ++t.rejected;
      }
    } catch (const std::string& what) {
      ++t.failed;
      if (t.failed <= 10) {
        const fs::path kept = file.string() + ".failure-" + std::to_string(t.failed);
        fs::copy_file(file, kept, fs::copy_options::overwrite_existing);
        ADD_FAILURE() << target << ": input " << t.tried << " (seed " << seed() << ") threw "
                      << what << "; the input is kept in " << kept.string();
      }
    }
  }
  watchdog.idle();
  fs::remove(file);
  std::cout << "fuzz " << target << ": " << t.tried << " inputs, " << t.accepted << " accepted, "
            << t.rejected << " rejected, " << t.failed << " failed (seed " << seed() << ", "
            << budget_seconds() << " s)\n";
  return t;
}

}  // namespace skinlab::fuzz

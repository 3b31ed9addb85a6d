#include "framework/core/interrupt.hpp"

#include <limits.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstring>
#include <mutex>
#include <string>
#include <unordered_map>

namespace skinlab {

namespace interrupt_detail {

/// One registered path. `state`: 0 free, 1 being filled (or claimed while dying), 2 ready.
struct Slot {
  std::atomic<int> state{0};
  char path[PATH_MAX];
};

std::array<Slot, kInterruptSlots> slots;
std::atomic<bool> dying{false};
// Which slot holds a path, for keep_on_interrupt (never touched by the handler).
std::mutex owners_mutex;
std::unordered_multimap<std::string, std::size_t> owners;
std::atomic<bool> reported{false};
char program_name[64] = "skinlab";
bool stderr_is_terminal = false;
constexpr std::array<int, 3> kSignals = {SIGINT, SIGTERM, SIGHUP};

void write_text(const char* text) {
  const std::size_t n = std::strlen(text);  // strlen is async-signal-safe
  std::size_t done = 0;
  while (done < n) {
    const ssize_t w = ::write(STDERR_FILENO, text + done, n - done);
    if (w <= 0) return;
    done += static_cast<std::size_t>(w);
  }
}

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
  }
}

void on_signal(int sig) {
  dying.store(true);
  for (Slot& slot : slots) {
    // A slot being filled by a thread that checked `dying` before it was set: its file cannot
    // exist yet (the owner creates it after registering); wait briefly, then skip it.
    int state = slot.state.load();
    for (int spin = 0; state == 1 && spin < 100000; ++spin) state = slot.state.load();
    if (state == 2) ::unlink(slot.path);
  }
  if (!reported.exchange(true)) {
    if (stderr_is_terminal) write_text("\n");
    write_text(program_name);
    write_text(": interrupted by ");
    write_text(signal_name(sig));
    write_text("; temporary files removed, no output half-written\n");
  }
  struct sigaction action {};
  action.sa_handler = SIG_DFL;
  sigemptyset(&action.sa_mask);
  ::sigaction(sig, &action, nullptr);
  ::raise(sig);  // delivered with the default action (end of the process) when this returns
}

}  // namespace interrupt_detail

namespace intr = interrupt_detail;

void install_interrupt_cleanup(const char* program) {
  std::strncpy(intr::program_name, program, sizeof(intr::program_name) - 1);
  intr::stderr_is_terminal = ::isatty(STDERR_FILENO) == 1;
  struct sigaction action {};
  action.sa_handler = intr::on_signal;
  sigemptyset(&action.sa_mask);
  for (int sig : intr::kSignals) sigaddset(&action.sa_mask, sig);
  for (int sig : intr::kSignals) {
    struct sigaction previous {};
    if (::sigaction(sig, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &action, nullptr);
  }
}

void remove_on_interrupt(const std::filesystem::path& path) {
  const std::string& text = path.native();
  if (text.size() >= PATH_MAX) return;
  for (std::size_t i = 0; i < intr::slots.size(); ++i) {
    int expected = 0;
    if (!intr::slots[i].state.compare_exchange_strong(expected, 1)) continue;
    // The handler is removing files: this one is not created yet, and the process is ending.
    while (intr::dying.load()) ::pause();
    std::memcpy(intr::slots[i].path, text.c_str(), text.size() + 1);
    {
      const std::lock_guard<std::mutex> lock(intr::owners_mutex);
      intr::owners.emplace(text, i);
    }
    intr::slots[i].state.store(2);
    return;
  }
}

void keep_on_interrupt(const std::filesystem::path& path) {
  const std::lock_guard<std::mutex> lock(intr::owners_mutex);
  const auto it = intr::owners.find(path.native());
  if (it == intr::owners.end()) return;
  intr::slots[it->second].state.store(0);
  intr::owners.erase(it);
}

}  // namespace skinlab

#pragma once
/// \file
/// Interrupted runs leave no temporary files. `install_interrupt_cleanup` installs handlers for
/// SIGINT, SIGTERM and SIGHUP that remove every path registered with `remove_on_interrupt`
/// (AtomicPath registers its temporary file, OutputLock its lock file), print one line on
/// stderr and end the process by the same signal with its default action, so the parent sees
/// it killed by that signal (a shell reports status 128 + signal: 130 for SIGINT). The handler
/// only calls unlink, write, sigaction and raise (async-signal-safe). A signal that was ignored
/// when the handlers were installed (a background job started with SIGINT ignored) stays
/// ignored.
///
/// Files under their final names are written whole by renaming (atomic_file.hpp), so an
/// interrupted command leaves the previous file or none. What an interruption keeps on purpose:
/// the finished per-character files of `skinlab prepare` in `<output>.partial/` (a later run
/// reuses them) and a run directory's complete files (`train --resume` continues from last.pt).
/// A staging directory of write_directory_atomic (`<target>.partial/`) is not removed; the next
/// write replaces it.
///
/// Limits: at most kInterruptSlots paths are registered at once (more are not tracked, and
/// stay behind if interrupted) and a path of PATH_MAX bytes or more is not tracked. SIGKILL and
/// crashes run no handler: AtomicPath's temporary files `.<name>.tmp-<pid>-<n>` then stay. A
/// thread that creates a registered file in the microseconds between the handler's unlink and
/// the end of the process leaves it behind.

#include <cstddef>
#include <filesystem>

namespace skinlab {

/// How many paths can be registered at the same time.
inline constexpr std::size_t kInterruptSlots = 256;

/// Installs the handlers of the file comment. `program` ("skinlab") starts the message line.
/// Call once, early in main, before any thread starts.
void install_interrupt_cleanup(const char* program);

/// Registers `path` for removal if the process is interrupted (see Limits). Thread-safe.
void remove_on_interrupt(const std::filesystem::path& path);

/// Unregisters `path` (one registration of it; nothing if it is not registered). Thread-safe;
/// call it when the owner has renamed or removed the path (an unlink of a missing path by an
/// interruption in between is harmless).
void keep_on_interrupt(const std::filesystem::path& path);

}  // namespace skinlab

#pragma once
/// \file
/// Local launcher of a data-parallel world (`skinlab train --nproc N`, `skinlab prepare
/// --nproc N`): starts N copies of this executable as worker processes, each with the
/// environment of PyTorch's launcher (RANK, WORLD_SIZE, LOCAL_RANK, MASTER_ADDR=127.0.0.1 and a
/// free MASTER_PORT; train/distributed.hpp reads them), and waits for them.
///
/// Failure: when a worker exits with a non-zero status or is killed, the others are sent
/// SIGTERM, given `grace` to exit and then SIGKILL, and the launch fails with an Error naming the
/// first worker that failed and how. The workers' own collectives also fail at once when a peer
/// closes its connections, so a run never hangs on a dead worker. A launcher that ends (Ctrl-C,
/// kill) sends its workers SIGTERM (PR_SET_PDEATHSIG).

#include <chrono>
#include <string>
#include <vector>

namespace skinlab {

struct LaunchOptions {
  int nproc = 1;
  std::vector<std::string> args;  ///< the workers' arguments after the program name
  std::chrono::seconds grace{10};
  /// Extra environment of every worker, "NAME=value".
  std::vector<std::string> environment;
};

/// Threads for each of `nproc` workers: `requested` when it is positive, else (0: every core)
/// this machine's cores shared out, at least 1.
int threads_per_worker(int requested, int nproc);

/// A TCP port on 127.0.0.1 that was free a moment ago (bound to port 0 and released).
int free_local_port();

/// Runs the workers to completion. Throws Error (see the file comment) when one fails, and
/// IoError when a process cannot be started.
void launch_local(const LaunchOptions& options);

}  // namespace skinlab

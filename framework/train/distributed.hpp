#pragma once
/// \file
/// Data-parallel training over torch's c10d with the Gloo backend (what libtorch-dev ships:
/// TCPStore for the rendezvous, ProcessGroupGloo for the collectives). We write no cluster
/// software of our own: a world is N processes that find each other through a TCP store at
/// MASTER_ADDR:MASTER_PORT, and every step all-reduces the gradients.
///
/// The world is described by the environment variables PyTorch's launcher sets, so a multi-node
/// run is started the usual way (one `skinlab train` per process, e.g. from a cluster's job
/// script):
///
///     MASTER_ADDR   host of rank 0's store (default 127.0.0.1)
///     MASTER_PORT   its port (default 29500)
///     WORLD_SIZE    number of processes (unset or 1: not distributed)
///     RANK          this process's rank, 0..WORLD_SIZE−1
///
/// `skinlab train --nproc N` (launch.hpp) starts N such processes on this machine.
///
/// What crosses the network per optimiser step: one all-reduce of every gradient, flattened into
/// one float32 buffer (4 bytes × parameters; HeterSkinNet at the paper's widths: 4 × 4.37 M ≈
/// 17.5 MB). Gloo's ring all-reduce sends and receives about 2 (N−1)/N of the buffer per
/// process. Once per epoch a few doubles (loss sums) are added over the world.

#include <torch/torch.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace skinlab::train {

struct WorldOptions {
  int rank = 0;
  int size = 1;
  std::string master_addr = "127.0.0.1";
  int master_port = 29500;
  /// How long a rendezvous or a collective may wait for the other processes before it fails
  /// (a process that dies closes its connections, which fails the others at once; this bounds
  /// a process that hangs).
  std::chrono::seconds timeout{300};

  /// From MASTER_ADDR, MASTER_PORT, WORLD_SIZE, RANK (and SKINLAB_DIST_TIMEOUT, seconds). Throws
  /// Error naming the variable for a value that is not a number or out of range.
  static WorldOptions from_environment();
  bool distributed() const { return size > 1; }
};

/// One process's membership of a world. With size 1 every collective is the identity and no
/// socket is opened.
class World {
 public:
  /// Connects to the store (rank 0 hosts it) and builds the Gloo process group. Throws Error
  /// naming MASTER_ADDR:MASTER_PORT when the others do not arrive within the timeout.
  explicit World(const WorldOptions& options);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  int rank() const { return options_.rank; }
  int size() const { return options_.size; }
  bool writer() const { return options_.rank == 0; }  ///< rank 0 writes files
  bool distributed() const { return options_.size > 1; }

  /// Rank 0's parameters and buffers into every process's `module` (same architecture).
  void broadcast_parameters(torch::nn::Module& module);
  /// Every gradient of `module` summed over the world (a parameter without a gradient counts as
  /// zero), in one all-reduce of a flat buffer.
  void sum_gradients(torch::nn::Module& module);
  /// Element-wise sums over the world (float64).
  std::vector<double> sum(const std::vector<double>& values);
  /// Every process's `text` (any bytes), in rank order, through the store. With `root_only`,
  /// only rank 0 receives them (the others get an empty list).
  std::vector<std::string> gather(const std::string& key, const std::string& text,
                                  bool root_only = false);
  /// Waits for every process.
  void barrier();

 private:
  struct Group;  ///< the store and the Gloo process group (distributed.cpp)
  [[noreturn]] void fail(const std::string& what, const std::exception& e) const;

  WorldOptions options_;
  std::unique_ptr<Group> group_;
};

}  // namespace skinlab::train

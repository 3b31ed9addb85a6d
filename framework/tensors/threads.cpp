#include "framework/tensors/threads.hpp"

#include <ATen/Parallel.h>
#include <torch/version.h>

#include <algorithm>
#include <string>
#include <thread>

#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"

namespace skinlab {

int torch_threads() { return at::get_num_threads(); }

int set_torch_threads(int n) {
  if (n < 0) throw Error("thread count must be >= 0 (0 = every hardware thread), got " + std::to_string(n));
  const int hardware = static_cast<int>(std::thread::hardware_concurrency());
  at::set_num_threads(n > 0 ? n : std::max(1, hardware));
  return at::get_num_threads();
}

namespace {

const bool libtorch_runtime_registered = [] {
  register_compute_runtime({"libtorch", TORCH_VERSION, &torch_threads});
  return true;
}();

}  // namespace

}  // namespace skinlab

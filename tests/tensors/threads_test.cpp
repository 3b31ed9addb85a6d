#include "framework/tensors/threads.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <thread>

#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

TEST(Environment, SetsTorchThreads) {
  EXPECT_EQ(set_torch_threads(1), 1);
  EXPECT_EQ(torch_threads(), 1);
  EXPECT_GE(set_torch_threads(0), 1);
  EXPECT_EQ(torch_threads(), static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
  testing::expect_error<Error>([] { set_torch_threads(-1); }, {"thread count"});
}

// The tensors layer registers libtorch with the core's environment record.
TEST(Environment, RecordsLibtorchAndItsThreads) {
  set_torch_threads(1);
  const nlohmann::json env = collect_environment(3, {"skinlab"});
  EXPECT_FALSE(env["libraries"]["libtorch"].get<std::string>().empty());
  EXPECT_EQ(env["threads"].get<int>(), 1);
  EXPECT_EQ(library_versions()["libtorch"], env["libraries"]["libtorch"]);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

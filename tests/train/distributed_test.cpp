// The world of data-parallel training (framework/train/distributed.hpp) as far as one process
// can see it: the environment PyTorch's launcher sets is read and checked, and a world of one
// leaves gradients, parameters and sums as they are. Two real processes are in
// tests/cli/distributed_cli_test.cpp.
#include "framework/train/distributed.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

#include "framework/core/error.hpp"
#include "tests/test_util.hpp"

namespace skinlab::train {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

/// Sets environment variables for the test's duration.
class Environment {
 public:
  explicit Environment(std::vector<std::pair<std::string, std::string>> values) : values_(std::move(values)) {
    for (const auto& [k, v] : values_) ::setenv(k.c_str(), v.c_str(), 1);
  }
  ~Environment() {
    for (const auto& [k, v] : values_) ::unsetenv(k.c_str());
  }

 private:
  std::vector<std::pair<std::string, std::string>> values_;
};

TEST(WorldOptions, ReadsTheLaunchersEnvironment) {
  {
    const WorldOptions alone = WorldOptions::from_environment();
    EXPECT_EQ(alone.size, 1);
    EXPECT_EQ(alone.rank, 0);
    EXPECT_FALSE(alone.distributed());
  }
  {
    const Environment env({{"WORLD_SIZE", "4"}, {"RANK", "3"}, {"MASTER_ADDR", "node7"},
                           {"MASTER_PORT", "29511"}, {"SKINLAB_DIST_TIMEOUT", "30"}});
    const WorldOptions o = WorldOptions::from_environment();
    EXPECT_EQ(o.size, 4);
    EXPECT_EQ(o.rank, 3);
    EXPECT_EQ(o.master_addr, "node7");
    EXPECT_EQ(o.master_port, 29511);
    EXPECT_EQ(o.timeout.count(), 30);
    EXPECT_TRUE(o.distributed());
  }
  {
    const Environment env({{"WORLD_SIZE", "2"}, {"RANK", "2"}});
    testing::expect_error<Error>([] { WorldOptions::from_environment(); }, {"RANK='2'", "0..1"});
  }
  {
    const Environment env({{"WORLD_SIZE", "two"}, {"RANK", "0"}});
    testing::expect_error<Error>([] { WorldOptions::from_environment(); }, {"WORLD_SIZE='two'"});
  }
}

TEST(World, OfOneProcessChangesNothing) {
  World world(WorldOptions{});
  EXPECT_TRUE(world.writer());
  EXPECT_FALSE(world.distributed());
  torch::manual_seed(0);
  torch::nn::Linear layer(3, 2);
  const torch::Tensor before = layer->weight.detach().clone();
  layer->forward(torch::ones({1, 3})).sum().backward();
  const torch::Tensor grad = layer->weight.grad().clone();
  world.broadcast_parameters(*layer);
  world.sum_gradients(*layer);
  EXPECT_TRUE(layer->weight.equal(before));
  EXPECT_TRUE(layer->weight.grad().equal(grad));
  EXPECT_EQ(world.sum({1.5, -2.0}), (std::vector<double>{1.5, -2.0}));
  EXPECT_EQ(world.gather("k", "text"), std::vector<std::string>{"text"});
  world.barrier();
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::train

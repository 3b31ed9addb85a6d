#include "framework/train/distributed.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>
#include <torch/csrc/distributed/c10d/TCPStore.hpp>

#include <cstdlib>

#include "framework/core/error.hpp"

namespace skinlab::train {

namespace {

/// The integer value of environment variable `name`, or `fallback` when it is unset or empty.
long env_integer(const char* name, long fallback, long lo, long hi) {
  const char* text = std::getenv(name);
  if (text == nullptr || *text == '\0') return fallback;
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  if (*end != '\0' || value < lo || value > hi) {
    throw Error(fmt::format("environment variable {}='{}': expected an integer in {}..{}", name,
                            text, lo, hi));
  }
  return value;
}

}  // namespace

WorldOptions WorldOptions::from_environment() {
  WorldOptions o;
  o.size = static_cast<int>(env_integer("WORLD_SIZE", 1, 1, 1 << 16));
  o.rank = static_cast<int>(env_integer("RANK", 0, 0, o.size - 1));
  o.master_port = static_cast<int>(env_integer("MASTER_PORT", 29500, 1, 65535));
  o.timeout = std::chrono::seconds(env_integer("SKINLAB_DIST_TIMEOUT", 300, 1, 86400));
  if (const char* addr = std::getenv("MASTER_ADDR"); addr != nullptr && *addr != '\0') {
    o.master_addr = addr;
  }
  return o;
}

struct World::Group {
  c10::intrusive_ptr<c10d::TCPStore> store;
  c10::intrusive_ptr<c10d::ProcessGroupGloo> gloo;
  std::int64_t gathers = 0;
};

World::World(const WorldOptions& options) : options_(options) {
  if (!distributed()) return;
  group_ = std::make_unique<Group>();
  const std::string where = fmt::format("{}:{}", options_.master_addr, options_.master_port);
  try {
    c10d::TCPStoreOptions store;
    store.port = static_cast<std::uint16_t>(options_.master_port);
    store.isServer = options_.rank == 0;
    store.numWorkers = static_cast<std::size_t>(options_.size);
    store.waitWorkers = true;
    store.timeout = options_.timeout;
    group_->store = c10::make_intrusive<c10d::TCPStore>(options_.master_addr, store);
    auto gloo = c10d::ProcessGroupGloo::Options::create(options_.timeout);
    // Gloo's transport binds to the address that reaches the master: loopback for a local
    // world, this host's interface towards MASTER_ADDR across nodes.
    const bool local = options_.master_addr == "127.0.0.1" || options_.master_addr == "localhost";
    gloo->devices.push_back(local ? c10d::ProcessGroupGloo::createDeviceForHostname("127.0.0.1")
                                  : c10d::ProcessGroupGloo::createDefaultDevice());
    group_->gloo = c10::make_intrusive<c10d::ProcessGroupGloo>(group_->store, options_.rank,
                                                               options_.size, gloo);
  } catch (const std::exception& e) {
    throw Error(fmt::format("rank {} of {}: could not join the world at {} within {} s: {}",
                            options_.rank, options_.size, where, options_.timeout.count(), e.what()));
  }
  spdlog::info("rank {} of {} joined the world at {} (Gloo)", options_.rank, options_.size, where);
}

World::~World() = default;

void World::fail(const std::string& what, const std::exception& e) const {
  throw Error(fmt::format("rank {} of {}: {} failed ({}); another process of the run stopped "
                          "or cannot be reached, so this one stops too",
                          options_.rank, options_.size, what, e.what()));
}

void World::broadcast_parameters(torch::nn::Module& module) {
  if (!distributed()) return;
  torch::NoGradGuard no_grad;
  std::vector<torch::Tensor> tensors;
  for (const auto& p : module.parameters()) tensors.push_back(p);
  for (const auto& b : module.buffers()) tensors.push_back(b);
  if (tensors.empty()) return;
  std::vector<torch::Tensor> flat;
  for (const auto& t : tensors) flat.push_back(t.detach().to(torch::kFloat64).reshape({-1}));
  std::vector<torch::Tensor> buffer{torch::cat(flat)};
  try {
    group_->gloo->broadcast(buffer)->wait();
  } catch (const std::exception& e) {
    fail("broadcasting the parameters", e);
  }
  std::int64_t at = 0;
  for (auto& t : tensors) {
    t.copy_(buffer[0].narrow(0, at, t.numel()).view(t.sizes()).to(t.scalar_type()));
    at += t.numel();
  }
}

void World::sum_gradients(torch::nn::Module& module) {
  if (!distributed()) return;
  torch::NoGradGuard no_grad;
  std::vector<torch::Tensor> parameters = module.parameters();
  std::vector<torch::Tensor> flat;
  for (const auto& p : parameters) {
    flat.push_back(p.grad().defined() ? p.grad().reshape({-1}) : torch::zeros({p.numel()}, p.options()));
  }
  if (flat.empty()) return;
  std::vector<torch::Tensor> buffer{torch::cat(flat)};
  try {
    group_->gloo->allreduce(buffer)->wait();
  } catch (const std::exception& e) {
    fail("all-reducing the gradients", e);
  }
  std::int64_t at = 0;
  for (auto& p : parameters) {
    const torch::Tensor summed = buffer[0].narrow(0, at, p.numel()).view(p.sizes());
    if (p.grad().defined()) {
      p.mutable_grad().copy_(summed);
    } else {
      p.mutable_grad() = summed.clone();
    }
    at += p.numel();
  }
}

std::vector<double> World::sum(const std::vector<double>& values) {
  if (!distributed() || values.empty()) return values;
  std::vector<torch::Tensor> buffer{torch::tensor(values, torch::kFloat64)};
  try {
    group_->gloo->allreduce(buffer)->wait();
  } catch (const std::exception& e) {
    fail("summing over the world", e);
  }
  const torch::Tensor& t = buffer[0];
  return {t.data_ptr<double>(), t.data_ptr<double>() + t.numel()};
}

std::vector<std::string> World::gather(const std::string& key, const std::string& text,
                                      bool root_only) {
  if (!distributed()) return {text};
  const std::string prefix = fmt::format("gather/{}/{}/", group_->gathers++, key);
  std::vector<std::string> out;
  try {
    group_->store->set(prefix + std::to_string(options_.rank),
                       std::vector<std::uint8_t>(text.begin(), text.end()));
    for (int r = 0; r < options_.size && !(root_only && !writer()); ++r) {
      const std::vector<std::uint8_t> bytes = group_->store->get(prefix + std::to_string(r));
      out.emplace_back(bytes.begin(), bytes.end());
    }
  } catch (const std::exception& e) {
    fail("gathering '" + key + "'", e);
  }
  return out;
}

void World::barrier() {
  if (!distributed()) return;
  try {
    group_->gloo->barrier()->wait();
  } catch (const std::exception& e) {
    fail("waiting for the other processes", e);
  }
}

}  // namespace skinlab::train

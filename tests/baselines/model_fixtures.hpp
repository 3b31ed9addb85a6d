#pragma once
// Shared by the learned-baseline tests (rignet_skin, neuroskinning): building a model of a known
// class from YAML, the synthetic tubes as tensors (cached), and the validity of a prediction.

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/tensors/tensors.hpp"
#include "tests/train/train_fixtures.hpp"

namespace skinlab::testing {

/// The model a `model:` YAML node builds, as class `T` (throws if the registry built another).
template <class T>
std::shared_ptr<T> make_model(const std::string& yaml) {
  auto model = model_registry().create(config::Config::parse(yaml, "m.yaml").root());
  auto typed = std::dynamic_pointer_cast<T>(model);
  if (!typed) throw std::runtime_error("the registry did not build the expected model class");
  return typed;
}

/// prepared_tube(index) as tensors with the Euclidean distance (K = 3), built once.
inline const data::CharacterTensors& tube_tensors(int index) {
  static std::map<int, data::CharacterTensors> cache;
  auto it = cache.find(index);
  if (it == cache.end()) {
    it = cache.emplace(index, data::to_tensors(prepared_tube(index), "euclidean")).first;
  }
  return it->second;
}

/// `w` is #V×3, finite, non-negative, rows summing to 1.
inline void expect_valid_rows(const torch::Tensor& w, const data::CharacterTensors& c) {
  ASSERT_EQ(w.sizes(), (std::vector<std::int64_t>{c.num_vertices(), 3}));
  EXPECT_TRUE(torch::isfinite(w).all().item<bool>());
  EXPECT_TRUE((w >= 0).all().item<bool>());
  EXPECT_TRUE(torch::allclose(w.sum(1), torch::ones({c.num_vertices()}), 1e-5, 1e-5));
}

}  // namespace skinlab::testing

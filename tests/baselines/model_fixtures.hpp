#pragma once
// Shared by the learned-baseline tests (rignet_skin, neuroskinning): building a model of a known
// class from YAML, the synthetic tubes as tensors (cached), the validity of a prediction, and a
// character with fewer bones than the model's K.

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

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

/// A model `m` built for K = `k` candidates, more than the tube's 6 bones, on the tube prepared
/// with one candidate per bone: its weights are a distribution over those 6 candidates, and
/// equal its weights on the tube with the candidates padded to K by hand (the nearest
/// repeated) renormalised over the first 6 slots, since a softmax over the own slots' logits
/// is exactly that. A tube with fewer candidates than K and than its bones is refused.
template <class M>
void expect_own_candidates_below_k(M& m, std::int64_t k) {
  m.eval();
  torch::NoGradGuard no_grad;
  const data::CharacterTensors c = data::to_tensors(prepared_tube(0, static_cast<int>(k)),
                                                    "euclidean");
  const std::int64_t own = c.num_bones(), nv = c.num_vertices();
  ASSERT_LT(own, k);
  ASSERT_EQ(c.top_k(), own);
  const torch::Tensor w = m.forward(c);
  ASSERT_EQ(w.sizes(), (std::vector<std::int64_t>{nv, own}));
  EXPECT_TRUE((w >= 0).all().item<bool>());
  EXPECT_TRUE(torch::allclose(w.sum(1), torch::ones({nv}), 1e-5, 1e-5));

  data::CharacterTensors by_hand = c;
  const auto pad = [&](const torch::Tensor& t) {
    std::vector<torch::Tensor> columns{t};
    for (std::int64_t j = own; j < k; ++j) columns.push_back(t.narrow(1, 0, 1));
    return torch::cat(columns, 1);
  };
  by_hand.topk_index = pad(c.topk_index);
  by_hand.topk_distance = pad(c.topk_distance);
  const torch::Tensor padded = m.forward(by_hand);
  ASSERT_EQ(padded.size(1), k);
  const torch::Tensor full = padded.narrow(1, 0, own);
  EXPECT_TRUE(torch::allclose(w, full / full.sum(1, true), 1e-5, 1e-6));

  const data::CharacterTensors too_few = data::to_tensors(prepared_tube(0, 2), "euclidean");
  EXPECT_THROW(m.forward(too_few), c10::Error);
}

}  // namespace skinlab::testing

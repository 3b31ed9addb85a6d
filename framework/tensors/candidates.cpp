#include "framework/tensors/candidates.hpp"

namespace skinlab::data {

CharacterTensors candidates_for_model(const CharacterTensors& c, std::int64_t k,
                                      const std::string& who) {
  const std::int64_t k_own = c.top_k();
  TORCH_CHECK(k_own == k || (k_own >= 1 && k_own < k && k_own == c.num_bones()), who,
              ": built for top_k = ", k, " but character '", c.name, "' has ", k_own,
              " candidate bones per vertex and ", c.num_bones(),
              " bones (set model.top_k to the dataset's top_k)");
  if (k_own == k) return c;
  // #V×k_own → #V×k, the nearest (first) column repeated.
  const auto pad = [&](const torch::Tensor& t) {
    return torch::cat({t, t.narrow(1, 0, 1).expand({t.size(0), k - k_own})}, 1);
  };
  CharacterTensors padded = c;
  padded.topk_index = pad(c.topk_index);
  padded.topk_distance = pad(c.topk_distance);
  for (auto& [name, prior] : padded.priors) prior = pad(prior);
  return padded;
}

}  // namespace skinlab::data

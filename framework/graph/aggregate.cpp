#include "framework/graph/aggregate.hpp"

namespace skinlab::graph {

namespace {
/// The index broadcast along the feature dimension (a stride-0 view, no copy).
torch::Tensor expand_index(const torch::Tensor& index, const torch::Tensor& src) {
  return index.view({-1, 1}).expand({index.size(0), src.size(1)});
}
}  // namespace

torch::Tensor scatter_rows(const torch::Tensor& src, const torch::Tensor& index, std::int64_t n,
                           c10::string_view reduce) {
  TORCH_CHECK(src.dim() == 2 && index.dim() == 1 && index.size(0) == src.size(0),
              "scatter_rows: expected #R×F rows and #R indices, got ", src.sizes(), " and ",
              index.sizes());
  const torch::Tensor out = torch::zeros({n, src.size(1)}, src.options());
  if (reduce == "sum") return out.index_add(0, index, src);
  return out.scatter_reduce(0, expand_index(index, src), src, reduce, /*include_self=*/false);
}

torch::Tensor count_rows(const torch::Tensor& index, std::int64_t n, torch::ScalarType dtype) {
  return torch::bincount(index, /*weights=*/{}, n).to(dtype);
}

torch::Tensor edge_conv_max(const torch::Tensor& x, const torch::Tensor& edges, MlpImpl& mlp,
                            bool self_loops) {
  const std::int64_t n = x.size(0), f = x.size(1);
  TORCH_CHECK(mlp.size() >= 1 && mlp.in_width() == 2 * f, "edge_conv_max: the MLP must take 2×",
              f, " inputs, it takes ", mlp.in_width());
  const torch::Tensor receiver = edges.select(1, 0), neighbour = edges.select(1, 1);
  const torch::Tensor& w = mlp.linear(0)->weight;  // F1 × 2F = [W1 | W2]
  const torch::Tensor w2 = w.narrow(1, f, f);
  const torch::Tensor wa = w.narrow(1, 0, f) + w2;
  const torch::Tensor& bias = mlp.linear(0)->bias;
  const torch::Tensor a = bias.defined() ? torch::addmm(bias, x, wa.t()) : x.matmul(wa.t());
  const torch::Tensor b = x.matmul(w2.t());  // first layer on edge (i, j): a_i − b_j

  if (mlp.size() == 1) {
    // max_j σ(a_i − b_j) = σ(a_i − min_j b_j) for non-decreasing σ.
    const torch::Tensor b_j = b.index_select(0, neighbour);
    const torch::Tensor index = receiver.view({-1, 1}).expand({receiver.size(0), b.size(1)});
    if (self_loops) {
      return mlp.activation(0, a - b.scatter_reduce(0, index, b_j, "amin", /*include_self=*/true));
    }
    const torch::Tensor b_min =
        torch::zeros_like(b).scatter_reduce(0, index, b_j, "amin", /*include_self=*/false);
    const torch::Tensor has_neighbour = count_rows(receiver, n, torch::kBool).view({-1, 1});
    return torch::where(has_neighbour, mlp.activation(0, a - b_min), torch::zeros_like(a));
  }

  const torch::Tensor messages = mlp.forward_from(
      1, mlp.activation(0, a.index_select(0, receiver) - b.index_select(0, neighbour)));
  const torch::Tensor index =
      receiver.view({-1, 1}).expand({receiver.size(0), messages.size(1)});
  if (self_loops) {
    const torch::Tensor self_messages = mlp.forward_from(1, mlp.activation(0, a - b));
    return self_messages.scatter_reduce(0, index, messages, "amax", /*include_self=*/true);
  }
  return torch::zeros({n, messages.size(1)}, messages.options())
      .scatter_reduce(0, index, messages, "amax", /*include_self=*/false);
}

}  // namespace skinlab::graph

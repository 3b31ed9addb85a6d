#pragma once
/// \file
/// Scatter/gather kernels shared by the graph ops: reductions of per-edge (or per vertex–bone
/// pair) rows into per-node rows with an index tensor, and EdgeConv's max aggregation
/// (HeterSkinNet Eq. 2, after Wang et al. 2019, DGCNN). Whole-tensor operations only;
/// differentiable in every floating input.

#include <torch/torch.h>

#include <cstdint>

#include "framework/graph/mlp.hpp"

namespace skinlab::graph {

/// #N×F: out[n] = reduce over the rows r of `src` (#R×F) with index[r] = n (#R int64, values in
/// [0, N)); `reduce` is "amax", "amin" or "sum". A node no row points to gets 0 (a defined,
/// gradient-free value). Ties of a max or min share the gradient equally.
torch::Tensor scatter_rows(const torch::Tensor& src, const torch::Tensor& index, std::int64_t n,
                           c10::string_view reduce);

/// #N: how many entries of `index` (int64, values in [0, N)) equal each node, as `dtype`.
torch::Tensor count_rows(const torch::Tensor& index, std::int64_t n, torch::ScalarType dtype);

/// EdgeConv with max aggregation on node features `x` (#N×F):
///
///     out_i = max over j in N(i) of MLP(x_i ‖ x_i − x_j)            (Eq. 2)
///
/// where N(i) = { j : (i, j) is a row of `edges` (#E×2, validated) }, plus i itself when
/// `self_loops`. `mlp` takes 2F inputs. Returns #N×mlp.out_width().
///
/// Nodes without neighbours: with `self_loops` (the default of every op) N(i) always holds i, so
/// out_i = MLP(x_i ‖ 0), the node's own transformed feature; this is what RigNet's EdgeConv does
/// (remove_self_loops, then add_self_loops) and what DGCNN gets implicitly, its k-NN including
/// the point itself. Since max is idempotent, a self-edge already present in `edges` changes
/// nothing. Without `self_loops`, a node with no neighbour gets the zero vector (PyG's empty max)
/// and no gradient.
///
/// Cost. The first layer is applied per node, not per edge: W [x_i ; x_i − x_j] + b =
/// (W₁ + W₂) x_i + b − W₂ x_j, so two #N×F₁ products replace one #E×F₁ product with 2F
/// inputs. With a one-layer MLP (the paper's W_s ∈ R^{2F×F'}), whose activation (LeakyReLU or
/// none) is non-decreasing, the max moves inside: max_j σ(a_i − b_j) = σ(a_i − min_j b_j), so no
/// per-edge MLP output is formed at all. Both are exact rewritings (tests compare with the
/// per-edge formula).
torch::Tensor edge_conv_max(const torch::Tensor& x, const torch::Tensor& edges, MlpImpl& mlp,
                            bool self_loops);

}  // namespace skinlab::graph

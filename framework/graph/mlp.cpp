#include "framework/graph/mlp.hpp"

#include "framework/graph/graph_op.hpp"

namespace skinlab::graph {

void kaiming_init(torch::nn::LinearImpl& linear) {
  torch::NoGradGuard no_grad;
  torch::nn::init::kaiming_normal_(linear.weight, kLeakySlope, torch::kFanIn, torch::kLeakyReLU);
  if (linear.bias.defined()) linear.bias.zero_();
}

MlpImpl::MlpImpl(std::int64_t in_width, MlpOptions options)
    : in_width_(in_width), options_(std::move(options)) {
  TORCH_CHECK(in_width >= 1, "mlp: input width must be ≥ 1, got ", in_width);
  TORCH_CHECK(options_.dropout >= 0 && options_.dropout < 1, "mlp: dropout must be in [0, 1), got ",
              options_.dropout);
  std::int64_t width = in_width;
  for (std::size_t i = 0; i < options_.widths.size(); ++i) {
    TORCH_CHECK(options_.widths[i] >= 1, "mlp: layer ", i, " width must be ≥ 1, got ",
                options_.widths[i]);
    torch::nn::Linear linear(width, options_.widths[i]);
    register_module("linear" + std::to_string(i), linear);
    kaiming_init(*linear);
    linears_.push_back(linear);
    width = options_.widths[i];
  }
}

std::int64_t MlpImpl::out_width() const {
  return linears_.empty() ? in_width_ : options_.widths.back();
}

torch::Tensor MlpImpl::activation(std::size_t i, torch::Tensor y) const {
  if (i + 1 < linears_.size() || options_.activate_last) return torch::leaky_relu(y, kLeakySlope);
  return y;
}

torch::Tensor MlpImpl::forward_from(std::size_t first, torch::Tensor x) {
  for (std::size_t i = first; i < linears_.size(); ++i) {
    if (i > 0 && options_.dropout > 0) x = torch::dropout(x, options_.dropout, is_training());
    x = activation(i, linears_[i]->forward(x));
  }
  return x;
}

torch::Tensor MlpImpl::forward(torch::Tensor x) {
  TORCH_CHECK(x.dim() == 2 && x.size(1) == in_width_, "mlp: expected N×", in_width_,
              " input, got shape ", x.sizes());
  return forward_from(0, std::move(x));
}

torch::Tensor MlpImpl::forward_gathered(const torch::Tensor& own, const torch::Tensor& table,
                                        const torch::Tensor& index, const torch::Tensor& shared) {
  TORCH_CHECK(own.dim() == 2 && table.dim() == 2 && index.dim() == 2 &&
                  index.size(0) == own.size(0) && index.scalar_type() == torch::kInt64,
              "mlp: forward_gathered expects #V×F own rows, a #B×F table and a #V×K int64 index, "
              "got ",
              own.sizes(), ", ", table.sizes(), " and ", index.sizes());
  const std::int64_t nv = own.size(0), k = index.size(1), f0 = own.size(1), f1 = table.size(1);
  const std::int64_t f2 = shared.defined() ? shared.size(1) : 0;
  TORCH_CHECK(!shared.defined() || (shared.dim() == 2 && shared.size(0) == 1),
              "mlp: forward_gathered expects a 1×F shared row, got ", shared.sizes());
  TORCH_CHECK(f0 + k * f1 + f2 == in_width_, "mlp: forward_gathered's blocks are ", f0, " + ", k,
              "×", f1, " + ", f2, " wide, the MLP takes ", in_width_);
  if (linears_.empty()) {
    std::vector<torch::Tensor> parts{
        own, table.index_select(0, index.reshape({-1})).view({nv, k * f1})};
    if (shared.defined()) parts.push_back(shared.expand({nv, f2}));
    return forward(torch::cat(parts, 1));
  }
  const torch::Tensor& w = linears_[0]->weight;  // out × (F₀ + K·F₁ + F₂)
  const torch::Tensor& bias = linears_[0]->bias;
  torch::Tensor bias_row = bias.defined() ? bias.view({1, -1}) : torch::zeros({1, w.size(0)}, w.options());
  if (shared.defined()) bias_row = torch::addmm(bias_row, shared, w.narrow(1, f0 + k * f1, f2).t());
  torch::Tensor y = torch::addmm(bias_row, own, w.narrow(1, 0, f0).t());
  for (std::int64_t j = 0; j < k; ++j) {
    const torch::Tensor per_row = table.matmul(w.narrow(1, f0 + j * f1, f1).t());
    y.add_(per_row.index_select(0, index.select(1, j)));
  }
  return forward_from(1, activation(0, std::move(y)));
}

}  // namespace skinlab::graph

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

}  // namespace skinlab::graph

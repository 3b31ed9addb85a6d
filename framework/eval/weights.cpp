#include "framework/eval/weights.hpp"

#include <cmath>
#include <vector>

namespace skinlab::eval {

namespace {

std::string shape(const torch::Tensor& t) {
  std::string out = "[";
  for (int64_t d = 0; d < t.dim(); ++d) out += (d ? ", " : "") + std::to_string(t.size(d));
  return out + "]";
}

RowMatrixXd to_matrix(const torch::Tensor& t, const std::string& context, const char* what) {
  // float32 (what models output) is read in place; anything else goes through float64.
  const torch::Tensor c = t.detach().to(torch::kCPU).contiguous();
  RowMatrixXd m;
  if (c.scalar_type() == torch::kFloat32) {
    m = Eigen::Map<const data::RowMatrixXf>(c.data_ptr<float>(), c.size(0), c.size(1))
            .cast<double>();
  } else {
    const torch::Tensor d = c.to(torch::kFloat64);
    m = Eigen::Map<const RowMatrixXd>(d.data_ptr<double>(), d.size(0), d.size(1));
  }
  if (m.size() > 0 && m.allFinite() && m.minCoeff() >= 0) return m;
  for (Eigen::Index v = 0; v < m.rows(); ++v) {  // find the first bad entry for the message
    for (Eigen::Index b = 0; b < m.cols(); ++b) {
      const double w = m(v, b);
      TORCH_CHECK(std::isfinite(w) && w >= 0, context, ": ", what, " weight of vertex ", v,
                  " on bone ", b, " is ", w, "; weights must be finite and ≥ 0");
    }
  }
  return m;
}

}  // namespace

std::string error_context(const MetricInputs& in, const std::string& metric) {
  std::string out = "metric '" + metric + "'";
  if (in.character) out += " (character '" + in.character->name + "')";
  return out;
}

WeightPair read_weights(const MetricInputs& in, const std::string& metric) {
  const std::string context = error_context(in, metric);
  TORCH_CHECK(in.pred.defined() && in.target.defined(), context,
              ": needs both a prediction and a target");
  TORCH_CHECK(in.pred.dim() == 2 && in.target.dim() == 2, context,
              ": prediction and target must be #V×#B, got shapes ", shape(in.pred), " and ",
              shape(in.target));
  TORCH_CHECK(in.pred.sizes() == in.target.sizes(), context, ": prediction shape ", shape(in.pred),
              " differs from target shape ", shape(in.target));
  TORCH_CHECK(in.pred.is_floating_point() && in.target.is_floating_point(), context,
              ": prediction and target must be floating-point tensors");
  if (in.character) {
    const auto& c = *in.character;
    TORCH_CHECK(in.pred.size(0) == c.num_vertices() && in.pred.size(1) == c.num_bones(), context,
                ": weights are ", shape(in.pred), " but the character has #V×#B = [",
                c.num_vertices(), ", ", c.num_bones(), "]");
  }
  return {to_matrix(in.pred, context, "predicted"), to_matrix(in.target, context, "target")};
}

geometry::SparseWeights joint_weights(const RowMatrixXd& W, const RowMatrixXi& bones,
                                      int num_joints) {
  TORCH_CHECK(bones.cols() == 2 && bones.rows() == W.cols(), "joint_weights: bones are ",
              bones.rows(), "×", bones.cols(), ", expected #B×2 with #B = ", W.cols());
  for (Eigen::Index b = 0; b < bones.rows(); ++b) {
    TORCH_CHECK(bones(b, 0) >= 0 && bones(b, 0) < num_joints, "joint_weights: bone ", b,
                " starts at joint ", bones(b, 0), ", outside [0, ", num_joints, ")");
  }
  geometry::SparseWeights out(W.rows(), num_joints);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(W.rows()) * 4);
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    for (Eigen::Index b = 0; b < W.cols(); ++b) {
      if (W(v, b) != 0) entries.emplace_back(v, bones(b, 0), W(v, b));
    }
  }
  out.setFromTriplets(entries.begin(), entries.end());  // sums bones sharing a start joint
  return out;
}

}  // namespace skinlab::eval

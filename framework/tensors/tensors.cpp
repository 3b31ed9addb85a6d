#include "framework/tensors/tensors.hpp"

#include <fmt/format.h>

#include "framework/core/error.hpp"
#include "framework/core/text.hpp"
#include "framework/data/preprocess.hpp"
#include "framework/geometry/orient_outward.hpp"
#include "framework/geometry/vertex_normals.hpp"

namespace skinlab::data {

namespace {

torch::Tensor to_float(const RowMatrixXf& m) {
  return torch::from_blob(const_cast<float*>(m.data()), {m.rows(), m.cols()}, torch::kFloat32)
      .clone();
}

}  // namespace

torch::Tensor to_float(const RowMatrixXd& m) {
  return torch::from_blob(const_cast<double*>(m.data()), {m.rows(), m.cols()}, torch::kFloat64)
      .to(torch::kFloat32);
}

torch::Tensor to_long(const RowMatrixXi& m) {
  return torch::from_blob(const_cast<int*>(m.data()), {m.rows(), m.cols()}, torch::kInt32)
      .to(torch::kInt64);
}

CharacterTensors to_tensors(const PreparedCharacter& character, const std::string& distance) {
  const auto it = character.distances.find(distance);
  if (it == character.distances.end()) {
    throw IoError("character '" + character.name + "' has no distance type '" + distance +
                  "'; it was prepared with: " + joined_keys(character.distances, "(none)"));
  }
  const DistanceData& d = it->second;
  const auto nv = static_cast<Eigen::Index>(character.num_vertices());
  const auto nb = static_cast<Eigen::Index>(character.num_bones());
  const std::string where = "character '" + character.name + "', distance '" + distance + "'";
  if (d.D.rows() != nv || d.D.cols() != nb || d.topk_index.rows() != nv ||
      d.topk_distance.rows() != nv || d.targets.rows() != nv ||
      d.topk_distance.cols() != d.topk_index.cols() || d.targets.cols() != d.topk_index.cols()) {
    throw IoError(where + ": D, top-K and targets do not have #V = " + std::to_string(nv) +
                  " rows and #B = " + std::to_string(nb) + " columns (D) / K columns");
  }

  CharacterTensors t;
  t.name = character.name;
  t.distance = distance;
  t.positions = to_float(character.V);
  {
    geometry::Mesh mesh{character.V, character.F};
    if (mesh.F.rows() > 0) mesh = geometry::orient_outward(mesh);
    t.normals = to_float(RowMatrixXd(geometry::vertex_normals(mesh)));
  }
  t.topk_index = to_long(d.topk_index);
  t.topk_distance = to_float(d.topk_distance);

  // Sec. 3.2: the network predicts a distribution over the K candidates only, so the target is
  // the candidates' weight renormalised; a row with no weight on any candidate stays zero.
  const torch::Tensor raw = to_float(d.targets);
  const torch::Tensor sums = raw.sum(1, /*keepdim=*/true);
  t.targets = torch::where(sums > 0, raw / sums.clamp_min(1e-30), torch::zeros_like(raw));

  // Full bone weights by the preprocessing's own rule (preprocess.hpp), from D as stored.
  const geometry::Skeleton skeleton = character.rig();
  if (character.weights.rows() == 0 && character.weights.cols() == 0) {
    // A character prepared for prediction (preprocess.hpp, PreprocessMode): no ground truth.
    t.bone_weights = torch::Tensor();
  } else {
    if (character.weights.rows() != nv || character.weights.cols() != character.num_joints()) {
      throw IoError(where + ": weights are not #V×#J");
    }
    const Eigen::MatrixXd Wb = bone_weights(character.weights, skeleton, d.D.cast<double>());
    t.bone_weights = to_float(RowMatrixXd(Wb));
  }

  for (const auto& [type, P] : character.priors) {
    if (P.rows() != nv || P.cols() != nb) {
      throw IoError(where + ": prior '" + type + "' is not #V×#B");
    }
    t.priors.emplace(type, to_float(P).gather(1, t.topk_index));
  }

  const RowMatrixXd segments = skeleton.bone_segments();  // Sec. 3.2's bone attribute
  t.bones = to_float(segments);
  t.bone_joints = to_long(character.bones);
  t.one_ring = to_long(character.one_ring_edges);
  t.geodesic = to_long(character.geodesic_edges);

  const auto n = static_cast<std::int64_t>(character.laplacian_values.size());
  if (character.laplacian_indices.rows() != n) {
    throw IoError(where + ": Laplacian has " + std::to_string(character.laplacian_indices.rows()) +
                  " index pairs for " + std::to_string(n) + " values");
  }
  const torch::Tensor indices = n > 0 ? to_long(character.laplacian_indices).t().contiguous()
                                      : torch::zeros({2, 0}, torch::kInt64);
  const torch::Tensor values =
      torch::from_blob(const_cast<double*>(character.laplacian_values.data()), {n}, torch::kFloat64)
          .to(torch::kFloat32);
  t.laplacian = torch::sparse_coo_tensor(indices, values, {nv, nv}).coalesce();
  return t;
}

const torch::Tensor& prior_of(const CharacterTensors& c, const std::string& name,
                              const std::string& who) {
  const auto it = c.priors.find(name);
  if (it == c.priors.end()) {
    throw Error(
        fmt::format("{}: character '{}' has no '{}' prior (it has: {}); prepare its dataset "
                    "with preprocess.priors: [{{type: {}}}]",
                    who, c.name, name, joined_keys(c.priors), name));
  }
  return it->second;
}

torch::Tensor scatter_to_bones(const torch::Tensor& pred, const torch::Tensor& topk_index,
                               std::int64_t num_bones) {
  TORCH_CHECK(pred.defined() && pred.dim() == 2 && pred.is_floating_point(),
              "scatter_to_bones: pred must be a #V×K floating tensor, got ",
              pred.defined() ? pred.sizes() : torch::IntArrayRef{});
  TORCH_CHECK(topk_index.defined() && topk_index.scalar_type() == torch::kInt64,
              "scatter_to_bones: topk_index must be an int64 tensor");
  TORCH_CHECK(topk_index.sizes() == pred.sizes(), "scatter_to_bones: pred is ", pred.sizes(),
              " but topk_index is ", topk_index.sizes());
  TORCH_CHECK(num_bones >= pred.size(1), "scatter_to_bones: ", pred.size(1),
              " candidates per vertex but only ", num_bones, " bones");
  if (topk_index.numel() > 0) {
    TORCH_CHECK(topk_index.min().item<std::int64_t>() >= 0 &&
                    topk_index.max().item<std::int64_t>() < num_bones,
                "scatter_to_bones: a candidate bone index is outside [0, ", num_bones, ")");
  }
  const torch::Tensor zeros = torch::zeros({pred.size(0), num_bones}, pred.options());
  return zeros.scatter(1, topk_index, pred);
}

}  // namespace skinlab::data

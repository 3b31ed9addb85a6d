#include "framework/eval/predictions.hpp"

#include <fmt/format.h>

#include "framework/core/error.hpp"
#include "framework/geometry/rig_io.hpp"
#include "framework/infer/map_back.hpp"

namespace skinlab::eval {

data::RowMatrixXf to_eigen(const torch::Tensor& t) {
  const torch::Tensor c = t.detach().to(torch::kFloat32).contiguous();
  TORCH_CHECK(c.dim() == 2, "to_eigen: expected a 2-D tensor, got ", c.sizes());
  data::RowMatrixXf out(c.size(0), c.size(1));
  std::copy(c.data_ptr<float>(), c.data_ptr<float>() + c.numel(), out.data());
  return out;
}

void write_rig_prediction(const std::filesystem::path& file, const data::PreparedCharacter& character,
                          const data::RowMatrixXf& W_source) {
  geometry::write_rig(file, infer::source_skeleton(character),
                      infer::joint_weights_of(W_source, character.bones, character.num_joints()));
}

PredictionFile::PredictionFile(const std::filesystem::path& target)
    : writer_(std::make_unique<data::H5Writer>(target)) {}

void PredictionFile::add(const data::PreparedCharacter& character, const std::string& distance,
                         const torch::Tensor& candidates, const torch::Tensor& bone_weights,
                         const data::RowMatrixXf& W_source) {
  const std::string g = "/characters/" + character.name + "/";
  const geometry::SparseWeights J =
      joint_weights_of(W_source, character.bones, character.num_joints());
  writer_->write(g + "weights", W_source);
  writer_->write(g + "joint_weights", data::RowMatrixXf(Eigen::MatrixXd(J).cast<float>()));
  writer_->write(g + "prepared_weights", to_eigen(bone_weights));
  writer_->write(g + "candidates", to_eigen(candidates));
  writer_->write(g + "topk_index", character.distances.at(distance).topk_index);
  writer_->write(g + "bones", character.bones);
  writer_->write_strings(g + "joint_names", character.joint_names);
  writer_->write(g + "vertex_map", character.vertex_map);
  names_.push_back(character.name);
}

void PredictionFile::set_attribute(const std::string& name, const std::string& value) {
  writer_->write_attribute("/", name, value);
}

void PredictionFile::set_attribute(const std::string& name, std::int64_t value) {
  writer_->write_attribute("/", name, value);
}

void PredictionFile::commit() {
  writer_->write_strings("/character_names", names_);
  writer_->commit();
}

}  // namespace skinlab::eval

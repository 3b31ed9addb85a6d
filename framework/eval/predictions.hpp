#pragma once
/// \file
/// Predicted skin weights written back for the characters they were predicted for:
/// mapped from the prepared (merged, subdivided) vertices to the ORIGINAL vertices of
/// the source mesh through PreparedCharacter::vertex_map, as per-joint weights in RigNet's rig
/// text format (geometry/rig_io.hpp) and as bone and joint weights in one HDF5 file.
///
/// Layout of the HDF5 file (`<run>/predictions/<part>.h5`), one group per character:
///
///     /characters/<name>/weights          #V_orig×#B float32 bone weights at the source vertices
///     /characters/<name>/joint_weights    #V_orig×#J float32 per-joint weights (rig text's)
///     /characters/<name>/prepared_weights #V×#B float32 at the prepared vertices
///     /characters/<name>/candidates       #V×K float32 the model's output over topk_index
///     /characters/<name>/topk_index       #V×K int32 candidate bones
///     /characters/<name>/bones            #B×2 int32 (start, end) joints
///     /characters/<name>/joint_names      #J strings
///     /characters/<name>/vertex_map       #V_orig int32
///     /character_names                    strings, in evaluation order
///     attributes on /: experiment, run, split, part, checkpoint, epoch, distance

#include <torch/torch.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/data/dataset_file.hpp"
#include "framework/data/h5.hpp"
#include "framework/geometry/skin_weights.hpp"
#include "framework/infer/map_back.hpp"

namespace skinlab::eval {

// Mapping a prediction back to the source character (to_source_vertices, joint_weights_of,
// source_skeleton) is torch-free and shared with the Eigen-only predictor: infer/map_back.hpp.
using infer::joint_weights_of;
using infer::source_skeleton;
using infer::to_source_vertices;

/// Writes the rig text of a prediction: `W_source` is #V_orig×#B bone weights at the source
/// vertices (to_source_vertices).
void write_rig_prediction(const std::filesystem::path& file,
                          const data::PreparedCharacter& character,
                          const data::RowMatrixXf& W_source);

/// Collects the predictions of a split part into one HDF5 file (written atomically on commit).
class PredictionFile {
 public:
  explicit PredictionFile(const std::filesystem::path& target);
  /// `candidates` is the model's #V×K output, `bone_weights` its #V×#B scatter; `W_source` the
  /// bone weights at the source vertices.
  void add(const data::PreparedCharacter& character, const std::string& distance,
           const torch::Tensor& candidates, const torch::Tensor& bone_weights,
           const data::RowMatrixXf& W_source);
  void set_attribute(const std::string& name, const std::string& value);
  void set_attribute(const std::string& name, std::int64_t value);
  void commit();

 private:
  std::unique_ptr<data::H5Writer> writer_;
  std::vector<std::string> names_;
};

/// A float32 #R×C tensor as an Eigen matrix.
data::RowMatrixXf to_eigen(const torch::Tensor& t);

}  // namespace skinlab::eval

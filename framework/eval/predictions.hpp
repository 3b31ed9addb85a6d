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

namespace skinlab::eval {

/// Rows of `W` (#V×C, prepared vertices) at the source vertices: row i of the result is row
/// vertex_map[i]. Throws Error for a map entry outside [0, #V).
data::RowMatrixXf to_source_vertices(const data::RowMatrixXf& W, const std::vector<int>& vertex_map);

/// #V×#J joint weights from #V×#B bone weights: a bone's weight belongs to its start joint
/// (RigNet; the inverse of the bone-level rule of data/preprocess.hpp). Exact zeros are not
/// stored; each value is the float32 sum rounded to its shortest decimal form.
geometry::SparseWeights joint_weights_of(const data::RowMatrixXf& W, const data::RowMatrixXi& bones,
                                         int num_joints);

/// The character's skeleton in its source file's frame (joint positions mapped through the
/// inverse of PreparedCharacter::normalisation), with joint names made writable in a rig file:
/// whitespace and '#' become '_', and a name that then collides gets a suffix `_2`, `_3`, ...
geometry::Skeleton source_skeleton(const data::PreparedCharacter& character);

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

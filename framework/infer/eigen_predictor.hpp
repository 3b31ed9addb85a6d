#pragma once
/// \file
/// A bundled model run without libtorch (`skinlab-predict`): the parameters and architecture of
/// `<dir>/parameters.h5` (infer/parameters.hpp) evaluated by the Eigen forward pass
/// (infer/network.hpp), with the preprocessing, candidate selection, pruning and mapping back
/// that `skinlab predict` uses (infer/prediction.hpp) and its preparation.yaml
/// (infer/model_dir.hpp).

#include <filesystem>
#include <string>

#include "framework/infer/network.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/infer/engine.hpp"

namespace skinlab::infer {

/// #V×K: `network`'s softmax over the candidate bones of `distance` (a key of
/// `character.distances`) for every vertex of `character` (prepared for prediction,
/// infer/prediction.hpp). Error naming the character when it lacks `distance`.
data::RowMatrixXf forward(const Network& network, const data::PreparedCharacter& character,
                          const std::string& distance);

class EigenPredictor final : public PredictEngine {
 public:
  /// Loads `dir` (a bundle, or any model directory with parameters.h5). IoError/ConfigError
  /// naming the file for a directory without parameters.h5 (written by `skinlab bundle`, or
  /// `skinlab export-parameters DIR` for an older bundle), a bad parameter file (Network::from)
  /// or a missing preparation.
  static EigenPredictor load(const std::filesystem::path& dir);

  Prediction predict(const geometry::Character& character, const PredictOptions& options = {},
                     StageTimes* times = nullptr) const override;
  const std::string& description() const override { return description_; }
  const std::string& distance() const override { return distance_; }
  const Network& network() const { return network_; }

 private:
  EigenPredictor(Network network, Preparation preparation, std::string distance,
                 std::string description);
  Network network_;
  Preparation preparation_;
  std::string distance_, description_;
};

}  // namespace skinlab::infer

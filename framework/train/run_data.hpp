#pragma once
/// \file
/// The data of a run: the dataset file of its `data:` section with the named split resolved,
/// and each character's tensors (data/tensors.hpp) for the configured distance type, converted
/// once and kept.

#include <map>
#include <string>
#include <vector>

#include "framework/data/dataset_file.hpp"
#include "framework/tensors/tensors.hpp"
#include "framework/train/run_options.hpp"

namespace skinlab::train {

/// The parts of a split, in the order the file stores them.
inline const std::vector<std::string> kSplitParts = {"train", "val", "test"};

class RunData {
 public:
  /// Reads `options.file` (data::read_dataset) and resolves `options.split`. Throws IoError
  /// naming the file for a missing or invalid dataset, and for a split the file does not have
  /// (listing the splits it has).
  explicit RunData(const DataOptions& options);

  const data::Dataset& dataset() const { return dataset_; }
  const DataOptions& options() const { return options_; }

  /// Dataset indices of one part ("train", "val" or "test") of the split. Throws Error listing
  /// the parts for any other name.
  const std::vector<int>& part(const std::string& name) const;

  /// Tensors of character `index` (converted on first use). Throws IoError when the character
  /// lacks the distance type.
  const data::CharacterTensors& tensors(int index);

  /// Converts every character of `part` now, so a missing distance type is reported before any
  /// training starts.
  void convert(const std::string& part);

 private:
  DataOptions options_;
  data::Dataset dataset_;
  data::Split split_;
  std::map<int, data::CharacterTensors> tensors_;
};

}  // namespace skinlab::train

#include "framework/train/run_data.hpp"

#include "framework/core/error.hpp"
#include "framework/core/text.hpp"
#include "framework/data/splits.hpp"

namespace skinlab::train {

namespace {

data::Dataset read(const DataOptions& options) {
  try {
    return data::read_dataset(options.file);
  } catch (const IoError& e) {
    throw IoError(std::string(e.what()) + " (data.file)");
  }
}

}  // namespace

RunData::RunData(const DataOptions& options) : options_(options), dataset_(read(options)) {
  const auto it = dataset_.splits.find(options.split);
  if (it == dataset_.splits.end()) {
    throw IoError(
        options.file + ": no split '" + options.split + "' (data.split); the file has " +
        (dataset_.splits.empty() ? "no splits" : "the splits: " + joined_keys(dataset_.splits)));
  }
  split_ = it->second;
  if (options.val_sources.empty()) return;
  const std::size_t n = dataset_.characters.size();
  std::vector<std::string> groups(n), sources(n);
  std::vector<bool> augmented(n);
  for (std::size_t i = 0; i < n; ++i) {
    const data::PreparedCharacter& c = dataset_.characters[i];
    groups[i] = c.variant_group();
    sources[i] = c.source;
    augmented[i] = c.is_augmented_copy();
  }
  try {
    split_ = data::validate_on_sources(split_, groups, sources, augmented, options.val_sources,
                                       options.file + ": split '" + options.split +
                                           "', data.val_sources");
  } catch (const Error& e) {
    throw IoError(e.what());
  }
}

const std::vector<int>& RunData::part(const std::string& name) const {
  if (name == "train") return split_.train;
  if (name == "val") return split_.val;
  if (name == "test") return split_.test;
  throw Error("unknown split part '" + name + "'; a split has the parts train, val and test");
}

const data::CharacterTensors& RunData::tensors(int index) {
  auto it = tensors_.find(index);
  if (it == tensors_.end()) {
    try {
      it = tensors_
               .emplace(index, data::to_tensors(
                                   dataset_.characters.at(static_cast<std::size_t>(index)),
                                   options_.distance))
               .first;
    } catch (const IoError& e) {
      throw IoError(options_.file + ": " + e.what() + " (data.distance)");
    }
  }
  return it->second;
}

void RunData::convert(const std::string& name) {
  for (int index : part(name)) tensors(index);
}

}  // namespace skinlab::train

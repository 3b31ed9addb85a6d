#pragma once
/// \file
/// The dataset card: a Markdown document generated from a dataset file
/// (datasets/FORMAT.md), never typed: counts per source and split, skeleton families, vertex
/// and bone histograms (PNG), every character with its group and split membership, every
/// excluded character with its reason, and the licences and attribution the sources require.
/// `skinlab dataset-card results/datasets/games.h5 --out datasets/README.md` writes the card and
/// its figures (`<out dir>/card/*.png`), each atomically.

#include <filesystem>
#include <string>

#include "framework/data/dataset_file.hpp"

namespace skinlab::report {

struct DatasetCardOptions {
  std::string command;  ///< the command line that generated the card, quoted in its header
  std::string image_dir = "card";  ///< relative to the card's directory
};

/// The card's Markdown for `dataset` read from `dataset_file`; figures are referenced under
/// `options.image_dir`.
std::string dataset_card_markdown(const data::Dataset& dataset,
                                  const std::filesystem::path& dataset_file,
                                  const DatasetCardOptions& options);

/// Writes the histograms into `<out dir>/<image_dir>/` and then the Markdown to `out`.
void write_dataset_card(const data::Dataset& dataset, const std::filesystem::path& dataset_file,
                        const std::filesystem::path& out, const DatasetCardOptions& options);

}  // namespace skinlab::report

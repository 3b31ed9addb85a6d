/// \file
/// `skinlab dataset-card <file.h5> [--out datasets/README.md]`: generates the dataset card
/// (framework/report/dataset_card.hpp) and its histograms from a dataset file.

#include <filesystem>
#include <iostream>

#include "framework/cli/commands.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/report/dataset_card.hpp"

namespace skinlab::cli {

Command add_dataset_card(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "dataset-card", "generate the dataset card (Markdown + PNG histograms) of a dataset file");
  struct Args {
    std::string file;
    std::string out = "datasets/README.md";
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("file", args->file, "dataset file (.h5)")->required();
  cmd->add_option("--out", args->out,
                  "card to write; figures go to <its dir>/card/ (README.md) or <its dir>/<stem>_card/")
      ->capture_default_str();
  return {cmd, [args] {
            const data::Dataset d = data::read_dataset(args->file);
            report::DatasetCardOptions options;
            options.command = "skinlab dataset-card " + args->file + " --out " + args->out;
            // several cards can share a directory (datasets/README.md, datasets/games_all.md)
            const std::string stem = std::filesystem::path(args->out).stem().string();
            if (stem != "README") options.image_dir = stem + "_card";
            report::write_dataset_card(d, args->file, args->out, options);
            std::cout << "wrote " << args->out << " (" << d.characters.size() << " characters, "
                      << d.excluded.size() << " excluded)\n";
            return 0;
          }};
}

}  // namespace skinlab::cli

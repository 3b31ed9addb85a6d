/// \file
/// `skinlab curves <run_dir> [--out <run_dir>/curves.png]`: the training curves of a run as a
/// PNG (framework/report/plot.hpp): training loss (blue) and validation loss (orange) per epoch,
/// read from the run's metrics.jsonl. The figure has no words (the built-in font has digits
/// only); the command prints the caption.

#include <fmt/format.h>

#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "framework/cli/commands.hpp"
#include "framework/core/error.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/report/plot.hpp"

namespace skinlab::cli {

Command add_curves(CLI::App& app) {
  auto* cmd = app.add_subcommand("curves", "training and validation loss per epoch as a PNG");
  struct Args {
    std::string run;
    std::string out;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("run", args->run, "run directory (results/<experiment>/<run_id>)")->required();
  cmd->add_option("--out", args->out, "PNG to write (default: <run>/curves.png)");
  return {cmd, [args] {
            const RunDir run = RunDir::open(args->run);
            const auto file = run.file("metrics.jsonl");
            std::ifstream in(file);
            if (!in) throw IoError(file.string() + ": cannot read (has the run trained an epoch?)");
            report::Series train{{}, {}, {70, 110, 170}}, val{{}, {}, {230, 120, 30}};
            int line_number = 0;
            for (std::string line; std::getline(in, line);) {
              ++line_number;
              if (line.empty()) continue;
              try {
                const auto j = nlohmann::json::parse(line);
                const double epoch = j.at("epoch").get<double>();
                train.x.push_back(epoch);
                train.y.push_back(j.at("train_loss").get<double>());
                val.x.push_back(epoch);
                val.y.push_back(j.at("val_loss").is_number() ? j["val_loss"].get<double>() : NAN);
              } catch (const nlohmann::json::exception& e) {
                throw IoError(fmt::format("{}:{}: not a metrics line ({})", file.string(),
                                          line_number, e.what()));
              }
            }
            if (train.x.empty()) throw IoError(file.string() + ": no epochs yet");
            const std::string out = args->out.empty() ? run.file("curves.png").string() : args->out;
            report::write_png(out, report::line_plot({train, val}));
            std::cout << fmt::format(
                "wrote {}: training loss (blue) and validation loss (orange) against the epoch, "
                "{} epochs of {}\n",
                out, train.x.size(), run.path().string());
            return 0;
          }};
}

}  // namespace skinlab::cli

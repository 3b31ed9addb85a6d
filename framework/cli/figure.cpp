/// \file
/// `skinlab figure <run_dir>... [--part test] [--characters a,b | --count N] [--l1-max 1]
/// [--out dir]`: per-vertex error maps of evaluated runs side by side (HeterSkinNet Fig. 7 and
/// 10: L1 error of the weights; and the deformation error of Sec. 4.3 per vertex), one PNG per
/// character and map, and one vertex-coloured PLY per run, character and map
/// (framework/report/mesh_figure.hpp). Reads each run's saved predictions
/// (`predictions/<part>.h5`, written by `skinlab eval`), the dataset its config names, and the
/// run's own `metrics:` options (pruning, poses), so the maps average to the run's eval numbers.
/// Writes `<out>/README.md` with the captions and the command.
///
/// Runs of the corrective task (`task: corrective`) get DenseGATs' error-colour figures instead
/// (experiments/densegats/corrective_figure.hpp): the ground truth and each run's deformed mesh
/// coloured by its per-vertex error in cm, at `--poses` evaluation poses per character.

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <numeric>

#include "experiments/densegats/corrective_figure.hpp"
#include "framework/cli/commands.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/data/h5.hpp"
#include "framework/data/tensors.hpp"
#include "framework/eval/avg_l1.hpp"
#include "framework/eval/deformation_error.hpp"
#include "framework/eval/evaluate.hpp"
#include "framework/report/mesh_figure.hpp"

namespace skinlab::cli {

namespace {

namespace fs = std::filesystem;

/// One evaluated run: its label, dataset, predictions and per-vertex metrics.
struct FigureRun {
  fs::path dir;
  std::string experiment;
  fs::path dataset;
  std::unique_ptr<data::H5Reader> predictions;
  std::string distance;
  std::shared_ptr<eval::AvgL1> l1;
  std::shared_ptr<eval::DeformationError> deformation;
};

FigureRun open_run(const std::string& dir, const std::string& part) {
  FigureRun r;
  const RunDir run = RunDir::open(dir);
  r.dir = run.path();
  const config::Config config = config::Config::load(run.file("config.yaml"));
  const config::Node root = config.root();
  r.experiment = root["experiment"].as<std::string>();
  r.dataset = root["data"]["file"].as<std::string>();
  const fs::path file = run.file("predictions") / (part + ".h5");
  if (!fs::exists(file)) {
    throw IoError(
        fmt::format("{}: no saved predictions for part '{}' (run `skinlab eval {} "
                    "--split {}` first)",
                    file.string(), part, dir, part));
  }
  r.predictions = std::make_unique<data::H5Reader>(file);
  r.distance = r.predictions->read_attribute("/", "distance");
  if (root["metrics"].exists()) {
    for (const auto& m : eval::make_metrics(root["metrics"])) {
      if (auto a = std::dynamic_pointer_cast<eval::AvgL1>(m)) r.l1 = a;
      if (auto d = std::dynamic_pointer_cast<eval::DeformationError>(m)) r.deformation = d;
    }
  }
  if (!r.l1) r.l1 = std::make_shared<eval::AvgL1>(eval::AvgL1::Options{});
  if (!r.deformation) {
    r.deformation = std::make_shared<eval::DeformationError>(eval::DeformationError::Options{});
  }
  return r;
}

/// One kind of map of a character: file suffix, PLY property, decimals of the means in the
/// README, colour-scale top, values (one vector per run) and caption (`{}`: the scale top).
struct ErrorMap {
  std::string suffix, property;
  int decimals;
  double vmax;
  const std::vector<std::vector<double>>* values;
  std::string caption;
};

/// One map's figure: a column per run (front view above the side view), a colour bar below.
report::Image panel(const data::PreparedCharacter& c,
                    const std::vector<std::vector<double>>& values, double vmax) {
  std::vector<report::Image> columns;
  for (const auto& v : values) {
    columns.push_back(report::front_and_side(c.V, c.F, report::colour_values(v, vmax)));
  }
  const int decimals = vmax >= 1 ? 1 : static_cast<int>(std::ceil(-std::log10(vmax))) + 1;
  const report::Image bar = report::colour_bar(240, 14, vmax, decimals);
  return report::compose_row(columns, 12, &bar);
}

}  // namespace

Command add_figure(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "figure", "per-vertex L1 and deformation error maps of evaluated runs (PNG and PLY)");
  struct Args {
    std::vector<std::string> runs;
    std::string part = "test";
    std::vector<std::string> characters;
    int count = 3;
    double l1_max = 1.0;
    int poses = 3;
    double error_max_cm = 0;
    std::string out;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("runs", args->runs, "evaluated run directories, one column each")->required();
  cmd->add_option("--part", args->part, "evaluated part (predictions/<part>.h5)")
      ->capture_default_str();
  cmd->add_option("--characters", args->characters, "characters to draw (default: --count)")
      ->delimiter(',');
  cmd->add_option("--count", args->count, "the first N characters of the part")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--l1-max", args->l1_max, "top of the L1 colour scale (L1 is in [0, 2])")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--poses", args->poses,
                  "corrective runs: evaluation poses per character, evenly spaced")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--error-max", args->error_max_cm,
                  "corrective runs: top of the error colour scale in cm (default: each "
                  "figure's 99th percentile)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--out", args->out, "output directory")->required();
  return {
      cmd, [args] {
        if (densegats::is_corrective_run(args->runs.front())) {
          densegats::CorrectiveFigureOptions o;
          o.part = args->part;
          o.characters = args->characters;
          o.count = args->count;
          o.poses = args->poses;
          o.error_max_cm = args->error_max_cm;
          o.out = args->out;
          o.command = "skinlab figure " + fmt::format("{}", fmt::join(args->runs, " ")) +
                      fmt::format(" --part {} --poses {} --out {}", args->part, args->poses,
                                  args->out);
          if (!args->characters.empty())
            o.command += fmt::format(" --characters {}", fmt::join(args->characters, ","));
          else
            o.command += fmt::format(" --count {}", args->count);
          if (args->error_max_cm > 0) o.command += fmt::format(" --error-max {}", args->error_max_cm);
          densegats::write_corrective_figures(args->runs, o);
          return 0;
        }
        std::vector<FigureRun> runs;
        for (const auto& dir : args->runs) runs.push_back(open_run(dir, args->part));
        std::vector<std::string> names = args->characters;
        if (names.empty()) {
          names = runs[0].predictions->read_strings("/character_names");
          if (static_cast<int>(names.size()) > args->count) names.resize(args->count);
        }
        std::map<fs::path, data::Dataset> datasets;
        for (const auto& r : runs) {
          if (!datasets.count(r.dataset))
            datasets.emplace(r.dataset, data::read_dataset(r.dataset));
        }
        const fs::path out = args->out;
        fs::create_directories(out);
        std::string readme = "# Per-vertex error maps\n\nGenerated by `skinlab figure";
        for (const auto& dir : args->runs) readme += " " + dir;
        readme += fmt::format(" --part {} --characters {} --l1-max {} --out {}`.\n\n", args->part,
                              fmt::join(names, ","), args->l1_max, args->out);
        readme += "Columns, left to right:";
        for (const auto& r : runs)
          readme += fmt::format(" `{}` ({})", r.experiment, r.dir.string());
        readme +=
            ". Top: the character seen from +Z; bottom: from +X. Colour: viridis from 0 (dark "
            "purple) to the scale's top (yellow; larger values saturate). PLY files with the "
            "same colours and the values as a vertex property are in one folder per run.\n\n";

        for (const auto& name : names) {
          std::vector<std::vector<double>> l1, deformation;
          const data::PreparedCharacter* character = nullptr;
          for (auto& r : runs) {
            const std::string group = "/characters/" + name;
            if (!r.predictions->has(group + "/prepared_weights")) {
              throw IoError(fmt::format("{}: character '{}' has no predictions for part '{}'",
                                        r.dir.string(), name, args->part));
            }
            const auto& chars = datasets.at(r.dataset).characters;
            const auto it = std::find_if(chars.begin(), chars.end(),
                                         [&](const auto& c) { return c.name == name; });
            if (it == chars.end()) {
              throw IoError(fmt::format("{}: no character '{}'", r.dataset.string(), name));
            }
            character = &*it;
            data::RowMatrixXf W = r.predictions->read_float(group + "/prepared_weights");
            const torch::Tensor pred =
                torch::from_blob(W.data(), {W.rows(), W.cols()}, torch::kFloat32).clone();
            const eval::MetricInputs in{pred, data::to_tensors(*it, r.distance).bone_weights, &*it};
            const Eigen::VectorXd e = r.l1->vertex_errors(in);
            l1.emplace_back(e.data(), e.data() + e.size());
            const Eigen::VectorXd d = r.deformation->vertex_distances(in).colwise().mean();
            deformation.emplace_back(d.data(), d.data() + d.size());
            fs::create_directories(out / r.experiment);
          }
          std::vector<double> all;
          for (const auto& d : deformation) all.insert(all.end(), d.begin(), d.end());
          const double deformation_max =
              report::nice_width(std::max(report::quantile(all, 0.99), 1e-6), 1);
          const std::vector<ErrorMap> maps = {
              {"l1", "l1_error", 4, args->l1_max, &l1,
               "per-vertex L1 error Σ_b |P − G| of the pruned predicted bone weights against the "
               "artist weights, scale 0 – {}."},
              {"deformation", "deformation_error", 6, deformation_max, &deformation,
               "per-vertex deformation error (distance between the vertex skinned with the "
               "predicted and with the artist weights, mean over the evaluation poses), scale 0 "
               "– {} m of the 1 m-tall normalised character."}};
          readme += fmt::format("## {}\n\n", name);
          for (const ErrorMap& map : maps) {
            const std::string png = name + "_" + map.suffix + ".png";
            report::write_png(out / png, panel(*character, *map.values, map.vmax));
            readme += fmt::format("![{}]({})\n\n`{}`: ", map.suffix, png, png) +
                      fmt::format(fmt::runtime(map.caption), map.vmax) + " Means:";
            for (std::size_t i = 0; i < runs.size(); ++i) {
              const std::vector<double>& v = (*map.values)[i];
              report::write_coloured_ply(
                  out / runs[i].experiment / (name + "_" + map.suffix + ".ply"), character->V,
                  character->F, report::colour_values(v, map.vmax), map.property, v,
                  fmt::format("{} {} part {}", runs[i].dir.string(), name, args->part));
              const double mean = std::accumulate(v.begin(), v.end(), 0.0) / v.size();
              readme += fmt::format(" {} {:.{}f};", runs[i].experiment, mean, map.decimals);
            }
            readme += "\n\n";
          }
          std::cout << fmt::format(
              "{}: wrote {}_l1.png and {}_deformation.png (deformation "
              "scale 0 - {} m)\n",
              name, (out / name).string(), name, deformation_max);
        }
        write_file_atomic(out / "README.md", readme);
        std::cout << "wrote " << (out / "README.md").string() << "\n";
        return 0;
      }};
}

}  // namespace skinlab::cli

#include "experiments/densegats/corrective_figure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>

#include "experiments/densegats/corrective_data.hpp"
#include "experiments/densegats/corrective_task.hpp"
#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/core/run_dir.hpp"
#include "framework/data/h5.hpp"
#include "framework/report/mesh_figure.hpp"
#include "framework/report/plot.hpp"
#include "framework/train/run_data.hpp"

namespace skinlab::densegats {

namespace fs = std::filesystem;

namespace {

/// Grey of the ground-truth column: no error is drawn on it.
constexpr report::Rgb kTruthGrey = {200, 200, 200};
/// Largest difference (cm) allowed between a saved error and the one rebuilt from the dataset.
constexpr double kErrorTolerance = 1e-3;

struct FigureRun {
  fs::path dir;
  std::string experiment, method;
  CorrectiveConfig config;
  std::unique_ptr<data::H5Reader> predictions;
};

FigureRun open_run(const std::string& dir, const std::string& part) {
  FigureRun r;
  const RunDir run = RunDir::open(dir);
  r.dir = run.path();
  r.config = CorrectiveConfig::from(config::Config::load(run.file("config.yaml")));
  r.experiment = r.config.run.experiment;
  const fs::path file = run.file("predictions") / (part + ".h5");
  if (!fs::exists(file)) {
    throw IoError(fmt::format("{}: no saved predictions for part '{}' (run `skinlab eval {} "
                              "--split {}` first)",
                              file.string(), part, dir, part));
  }
  r.predictions = std::make_unique<data::H5Reader>(
      file, "written by an older skinlab: run `skinlab eval " + dir + " --split " + part +
                "` again with this build");
  if (!r.predictions->has_attribute("/", "task") ||
      r.predictions->read_attribute("/", "task") != "corrective") {
    throw IoError(file.string() + ": not the predictions of a corrective evaluation (no "
                                  "task: corrective attribute); evaluate the run again");
  }
  r.method = r.predictions->read_attribute("/", "method");
  return r;
}

}  // namespace

void write_corrective_figures(const report::FigureOptions& options, const std::string& command) {
  const std::vector<std::string>& run_dirs = options.runs;
  if (run_dirs.empty()) throw Error("corrective figures: no run given");
  std::vector<FigureRun> runs;
  for (const auto& dir : run_dirs) runs.push_back(open_run(dir, options.part));
  const CorrectiveConfig& first = runs.front().config;
  for (const FigureRun& r : runs) {
    if (r.config.run.data.file != first.run.data.file) {
      throw IoError(fmt::format("{}: evaluated on {}, but {} on {}; a figure compares runs on "
                                "one dataset",
                                r.dir.string(), r.config.run.data.file,
                                runs.front().dir.string(), first.run.data.file));
    }
  }

  const train::RunData run_data(first.run.data);
  const CorrectiveData data(run_data.dataset(), first.run.data.file, first.corrective);
  std::vector<std::string> names = options.characters;
  if (names.empty()) {
    names = runs.front().predictions->read_strings("/character_names");
    if (static_cast<int>(names.size()) > options.count) names.resize(static_cast<std::size_t>(options.count));
  }

  // Everything is read and checked before the first file is written.
  struct Panel {
    std::string character;
    int pose = 0;
    const CorrectiveCharacter* ch = nullptr;
    Eigen::MatrixXd target;
    std::vector<Eigen::MatrixXd> meshes;      // per run
    std::vector<std::vector<double>> errors;  // per run
    double vmax = 0;
  };
  std::vector<Panel> panels;
  for (const std::string& name : names) {
    const auto& chars = data.characters();
    const auto it = std::find_if(chars.begin(), chars.end(),
                                 [&](const CorrectiveCharacter& c) { return c.name == name; });
    if (it == chars.end()) {
      throw IoError(fmt::format("{}: no character '{}' of skeleton family '{}' with clips",
                                first.run.data.file, name, first.corrective.skeleton));
    }
    const int index = static_cast<int>(it - chars.begin());
    const auto V = static_cast<Eigen::Index>(it->num_vertices());
    const std::string group = "/characters/" + name;
    std::vector<int> poses;
    std::vector<data::RowMatrixXf> corrections, errors;  // per run, every saved pose
    for (const FigureRun& r : runs) {
      if (!r.predictions->has(group + "/poses")) {
        throw IoError(fmt::format("{}: character '{}' has no predictions for part '{}'",
                                  r.dir.string(), name, options.part));
      }
      const std::vector<int> saved = r.predictions->read_ints(group + "/poses");
      if (poses.empty()) poses = saved;
      if (saved != poses) {
        throw IoError(fmt::format("{}: character '{}' was evaluated at other poses than in {} "
                                  "(corrective.eval_poses or frame_stride differ)",
                                  r.dir.string(), name, runs.front().dir.string()));
      }
      corrections.push_back(r.predictions->read_float(group + "/correction_cm"));
      errors.push_back(r.predictions->read_float(group + "/error_cm"));
      if (corrections.back().rows() != V * static_cast<Eigen::Index>(poses.size()) ||
          corrections.back().cols() != 3 ||
          errors.back().rows() != static_cast<Eigen::Index>(poses.size()) ||
          errors.back().cols() != V) {
        throw IoError(fmt::format("{}: character '{}' has {}×{} corrections and {}×{} errors; "
                                  "{} poses of {} vertices expected",
                                  r.dir.string(), name, corrections.back().rows(),
                                  corrections.back().cols(), errors.back().rows(),
                                  errors.back().cols(), poses.size(), V));
      }
    }
    for (int k : evenly_spaced(poses.size(), options.poses)) {
      const int pose = poses[static_cast<std::size_t>(k)];
      if (pose < 0 || pose >= static_cast<int>(it->poses.size())) {
        throw IoError(fmt::format("{}: character '{}' pose {} is not in the dataset's pose list "
                                  "({} poses)", runs.front().dir.string(), name, pose,
                                  it->poses.size()));
      }
      const CorrectiveSample s = data.sample(index, pose);
      Panel p;
      p.character = name;
      p.pose = pose;
      p.ch = &*it;
      p.target = s.target;
      std::vector<double> all;
      for (std::size_t i = 0; i < runs.size(); ++i) {
        const FigureRun& r = runs[i];
        const Eigen::MatrixXd correction =
            corrections[i].middleRows(static_cast<Eigen::Index>(k) * V, V).cast<double>();
        const Eigen::VectorXd error = (correction - s.displacement).rowwise().norm();
        const double drift =
            (error - errors[i].row(k).transpose().cast<double>()).cwiseAbs().maxCoeff();
        if (drift > kErrorTolerance) {
          throw IoError(fmt::format("{}: character '{}' pose {}: the saved errors differ from "
                                    "those rebuilt from {} by up to {:.3g} cm; the dataset or "
                                    "the task's options changed since `skinlab eval`",
                                    r.dir.string(), name, pose, first.run.data.file, drift));
        }
        p.meshes.push_back(s.lbs + correction / data.cm_per_unit());
        p.errors.emplace_back(error.data(), error.data() + error.size());
        all.insert(all.end(), error.data(), error.data() + error.size());
      }
      p.vmax = options.error_max_cm > 0
                   ? options.error_max_cm
                   : report::nice_width(std::max(report::quantile(all, 0.99), 1e-3), 1);
      panels.push_back(std::move(p));
    }
  }

  fs::create_directories(options.out);
  std::string readme = "# Per-vertex error of corrective deformation (DenseGATs Fig. 8-10)\n\n";
  if (!command.empty()) readme += "Generated by `" + command + "`.\n\n";
  readme += "Columns, left to right: the ground truth (Delta Mush applied to the artist-weighted "
            "LBS mesh; grey), then";
  for (const FigureRun& r : runs)
    readme += fmt::format(" `{}` ({}, {})", r.experiment, r.method, r.dir.string());
  readme += fmt::format(
      ". Each run's column is its deformed mesh (LBS plus its predicted correction) coloured by "
      "each vertex's distance to the ground truth in cm at {} m: viridis from 0 (dark purple) to "
      "the figure's scale top (yellow; larger errors saturate). Top: seen from +Z; bottom: from "
      "+X. The root joint stays at its bind pose (the clip's global motion is removed). PLY "
      "files with the same colours and the errors as a vertex property are in one folder per "
      "run.\n\n",
      first.corrective.height_m);
  for (const Panel& p : panels) {
    const std::string stem = fmt::format("{}_pose{}", p.character, p.pose);
    const PoseRef ref = p.ch->poses[static_cast<std::size_t>(p.pose)];
    const PooledClip& clip = data.clips()[static_cast<std::size_t>(ref.clip)];
    std::vector<report::Image> columns{
        report::front_and_side(p.target, p.ch->mesh.F,
              std::vector<report::Rgb>(static_cast<std::size_t>(p.target.rows()), kTruthGrey))};
    readme += fmt::format("## {}, pose {} (clip `{}`, frame {})\n\n![{}]({}.png)\n\nScale 0 – {} "
                          "cm. Mean / max error (cm):",
                          p.character, p.pose, clip.name, ref.frame, stem, stem, p.vmax);
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const std::vector<double>& e = p.errors[i];
      const std::vector<report::Rgb> colours = report::colour_values(e, p.vmax);
      columns.push_back(report::front_and_side(p.meshes[i], p.ch->mesh.F, colours));
      fs::create_directories(options.out / runs[i].experiment);
      report::write_coloured_ply(options.out / runs[i].experiment / (stem + ".ply"), p.meshes[i],
                                 p.ch->mesh.F, colours, "error_cm", e,
                                 fmt::format("{} {} pose {} part {}", runs[i].dir.string(),
                                             p.character, p.pose, options.part));
      double sum = 0;
      for (double x : e) sum += x;
      readme += fmt::format(" {} {:.3f} / {:.2f};", runs[i].experiment,
                            sum / static_cast<double>(e.size()), *std::max_element(e.begin(), e.end()));
    }
    readme += "\n\n";
    const int decimals =
        p.vmax >= 1 ? 1 : static_cast<int>(std::ceil(-std::log10(p.vmax))) + 1;
    const report::Image bar = report::colour_bar(240, 14, p.vmax, decimals);
    report::write_png(options.out / (stem + ".png"), report::compose_row(columns, 12, &bar));
    std::cout << fmt::format("{}: wrote {}.png (scale 0 - {} cm)\n", p.character,
                             (options.out / stem).string(), p.vmax);
  }
  write_file_atomic(options.out / "README.md", readme);
  std::cout << "wrote " << (options.out / "README.md").string() << "\n";
}

}  // namespace skinlab::densegats

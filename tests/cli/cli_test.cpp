// The `skinlab` binary, run as a user runs it: exit status, stdout and stderr.

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "framework/core/atomic_file.hpp"
#include "framework/data/h5.hpp"
#include "framework/geometry/obj_io.hpp"
#include "tests/cli/cli_run.hpp"
#include "tests/geometry/test_meshes.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::Result;
using testing::run;
using testing::TempDir;

/// Whether Markdown `table` has the row of `experiment`'s run `run_id`. The run id carries the
/// dirty mark † when the tests run from a modified source tree, which a test cannot choose.
bool has_row(const std::string& table, const std::string& experiment, const std::string& run_id) {
  const std::string row = "| " + experiment + " | " + run_id;
  return table.find(row + " | ") != std::string::npos ||
         table.find(row + "† | ") != std::string::npos;
}

TEST(Cli, InfoListsEveryRegistry) {
  const Result r = run("info");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* line : {"distance:", "graph_op:", "model:", "metric:", "dataset:",
                           "loss: kl, laplacian_smoothing, mse, prior_kl, soft_cross_entropy", "libtorch:"}) {
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
  }
  const Result j = run("info --json");
  ASSERT_EQ(j.status, 0) << j.err;
  const auto info = nlohmann::json::parse(j.out);
  EXPECT_EQ(info["registries"]["loss"].size(), 5u);
  EXPECT_TRUE(info["registries"].contains("dataset"));
}

TEST(Cli, ConfigPrintsTheMergedResultWithOverrides) {
  const Result r = run("config configs/ablations/no_smoothing.yaml seed=3 losses.0.weight=2");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("seed: 3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("results_dir: results"), std::string::npos) << r.out;  // from base.yaml
  EXPECT_NE(r.out.find("experiment: heterskinnet_no_smoothing"), std::string::npos);
  EXPECT_NE(r.out.find("weight: 2"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("laplacian_smoothing"), std::string::npos) << "list must be replaced";
  EXPECT_EQ(r.out.find("_base_"), std::string::npos);
}

TEST(Cli, UnknownFieldIsReportedWithFileLineAndKey) {
  TempDir dir;
  const auto file = dir.write("bad.yaml", "_base_: " + std::string(SKINLAB_SOURCE_DIR) +
                                              "/configs/heterskinnet.yaml\nsede: 3\n");
  const Result r = run("config " + file.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(r.out.empty()) << "nothing printed on error";
  EXPECT_NE(r.err.find("skinlab: error: " + file.string() + ":2: sede: unknown field"),
            std::string::npos) << r.err;
  EXPECT_NE(r.err.find("did you mean 'seed'?"), std::string::npos) << r.err;
}

TEST(Cli, UnknownTypeListsTheKnownTypes) {
  const Result r = run("config configs/heterskinnet.yaml losses.1.type=laplacian");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("losses[1]: unknown loss type 'laplacian'; known loss types: kl, "
                       "laplacian_smoothing, mse, prior_kl, soft_cross_entropy"),
            std::string::npos) << r.err;
  const Result m = run("config configs/heterskinnet.yaml model.type=heterskinet");
  EXPECT_EQ(m.status, 1);
  EXPECT_NE(m.err.find("unknown model type 'heterskinet'; known model types: heterskinnet"),
            std::string::npos) << m.err;
}

TEST(Cli, ConfigValidatesTheMetricsOfBaseYaml) {
  const Result ok = run("config configs/heterskinnet.yaml");
  ASSERT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.out.find("type: deformation_error"), std::string::npos) << ok.out;
  const Result bad = run("config configs/heterskinnet.yaml metrics.0.average=mean");
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("average: must be 'entries' or 'vertices', got 'mean'"),
            std::string::npos) << bad.err;
}

TEST(Cli, WrongTypeMissingFileAndBadUsage) {
  const Result t = run("config configs/heterskinnet.yaml seed=abc");
  EXPECT_EQ(t.status, 1);
  EXPECT_NE(t.err.find("seed: expected an integer, got 'abc'"), std::string::npos) << t.err;
  const Result f = run("config configs/does_not_exist.yaml");
  EXPECT_EQ(f.status, 1);
  EXPECT_NE(f.err.find("configs/does_not_exist.yaml: config file does not exist"),
            std::string::npos) << f.err;
  const Result u = run("");
  EXPECT_NE(u.status, 0);
  const Result l = run("--log-level loud info");
  EXPECT_EQ(l.status, 1);
  EXPECT_NE(l.err.find("unknown log level 'loud'"), std::string::npos) << l.err;
}

TEST(Cli, DistanceOfARealCharacterToHdf5AndCsv) {
  TempDir dir;
  const std::string player =
      "/usr/share/games/minetest/games/minetest_game/mods/player_api/models/character.b3d";
  const Result r = run("distance " + player + " --type hollow_dist --option resolution=32 --out " +
                       (dir / "D.h5").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("character: 168 vertices, 6 joints, 10 bones"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "D.h5"));
  const Result c = run("distance " + player + " --type euclidean --out " + (dir / "D.csv").string());
  ASSERT_EQ(c.status, 0) << c.err;
  const std::string csv = read_file(dir / "D.csv");
  EXPECT_EQ(csv.rfind("vertex,Body->Head,", 0), 0u) << csv.substr(0, 200);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 169);  // header + one line per vertex

  const Result bad = run("distance " + player + " --type hollow_dist --option resolution=4");
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("resolution: must be at least 8"), std::string::npos) << bad.err;
  const Result ext = run("distance " + player + " --type euclidean --out " + (dir / "D.txt").string());
  EXPECT_EQ(ext.status, 1);
  EXPECT_NE(ext.err.find("unknown output type '.txt'"), std::string::npos) << ext.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "D.txt"));
}

TEST(Cli, PrepareAndDatasetInfoOnTheMinetestConfig) {
  TempDir dir;
  const std::string out = (dir / "minetest.h5").string();
  const Result r = run("prepare configs/datasets/minetest.yaml output=" + out +
                       " distances.0.resolution=32 --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("prepared " + out + ": 1 characters (1 computed, 0 reused), 0 excluded"),
            std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(out + ".partial"));

  const Result info = run("dataset-info " + out);
  ASSERT_EQ(info.status, 0) << info.err;
  for (const std::string part :
       {"format_version 3", "characters: 1", "character: ", "168 original", "6 joints, 10 bones",
        "distances: euclidean (K=3), hollow_dist (K=3)", "skeleton minetest_player",
        "group character", "licence CC-BY-SA-3.0", "splits: 1", "random: train 1, val 0, test 0",
        "excluded: 0"}) {
    EXPECT_NE(info.out.find(part), std::string::npos) << part << "\n" << info.out;
  }

  const Result foreign = run("dataset-info configs/datasets/minetest.yaml");
  EXPECT_EQ(foreign.status, 1);
  EXPECT_NE(foreign.err.find("skinlab: error: configs/datasets/minetest.yaml: not an HDF5 file"),
            std::string::npos) << foreign.err;
  const Result typo = run("prepare configs/datasets/minetest.yaml output=" + out +
                          " preprocess.topk=2");
  EXPECT_EQ(typo.status, 1);
  EXPECT_NE(typo.err.find("preprocess.topk: unknown field"), std::string::npos) << typo.err;
}

TEST(Cli, TrainAndEvalReportBadInputsBeforeCreatingARun) {
  TempDir dir;
  const std::string base = "_base_: " + std::string(SKINLAB_SOURCE_DIR) + "/configs/base.yaml\n" +
                           "experiment: cli_train\nresults_dir: " + (dir / "results").string() +
                           "\nlosses: [{type: kl}]\n";
  const auto no_model = dir.write("no_model.yaml", base + "data: {file: " + (dir / "d.h5").string() + "}\n");
  const Result m = run("train " + no_model.string());
  EXPECT_EQ(m.status, 1);
  EXPECT_NE(m.err.find("no_model.yaml: training needs a 'model' section"), std::string::npos) << m.err;

  const Result lr = run("train " + no_model.string() + " train.lr=0");
  EXPECT_EQ(lr.status, 1);
  EXPECT_NE(lr.err.find("train.lr: must be a positive number"), std::string::npos) << lr.err;

  const auto bad_key = dir.write("bad_key.yaml", base + "train:\n  epocs: 3\n");
  const Result k = run("train " + bad_key.string());
  EXPECT_EQ(k.status, 1);
  EXPECT_NE(k.err.find("bad_key.yaml:6: train.epocs: unknown field of the train section"),
            std::string::npos) << k.err;

  const auto unknown = dir.write("unknown.yaml", base + "model: {type: no_such_model}\n");
  const Result u = run("train " + unknown.string());
  EXPECT_EQ(u.status, 1);
  EXPECT_NE(u.err.find("unknown model type 'no_such_model'"), std::string::npos) << u.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "results")) << "no run directory on errors";

  const Result none = run("train");
  EXPECT_EQ(none.status, 1);
  EXPECT_NE(none.err.find("give an experiment config, or --resume <run_dir>"), std::string::npos);
  const Result resume = run("train --resume " + (dir / "nowhere").string());
  EXPECT_EQ(resume.status, 1);
  EXPECT_NE(resume.err.find("nowhere: run directory does not exist"), std::string::npos) << resume.err;

  const Result trained_first = run("eval configs/heterskinnet.yaml");
  EXPECT_EQ(trained_first.status, 1);
  EXPECT_NE(trained_first.err.find("configs/heterskinnet.yaml: has a 'model', which must be "
                                   "trained first"),
            std::string::npos) << trained_first.err;
  const Result e = run("eval " + (dir / "nowhere").string());
  EXPECT_EQ(e.status, 1);
  EXPECT_NE(e.err.find("nowhere: run directory does not exist"), std::string::npos) << e.err;
  dir.write("run/config.yaml", "experiment: x\n");
  const Result c = run("eval " + (dir / "run").string() + " --checkpoint first");
  EXPECT_EQ(c.status, 1);
  EXPECT_NE(c.err.find("unknown checkpoint 'first'; choose best or last"), std::string::npos) << c.err;
  const Result o = run("train --resume " + (dir / "run").string() + " seed=3");
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("overrides would change the run's config"), std::string::npos) << o.err;
}

// What CI runs of the main job's path: configs/smoke.yaml (HeterSkinNet with tiny widths) on the
// bundled real 0 A.D. subset, prepared here, trained and evaluated through the binary.
/// configs/sweeps/smoke_table3.yaml on a prepared bundled subset `data`: every method of Table 3
/// (the learned baselines with tiny widths) trains or runs, is evaluated on the same test
/// characters and gets a row with finite metrics in the table, with an ANOVA row against the
/// first entry.
void check_smoke_table3(const TempDir& dir, const std::string& data, const std::string& results) {
  std::string sweep = read_file(std::filesystem::path(SKINLAB_SOURCE_DIR) / "configs" / "sweeps" /
                                "smoke_table3.yaml");
  const std::string out_line = "out: results/tables/smoke_table3.md";
  const auto at = sweep.find(out_line);
  ASSERT_NE(at, std::string::npos) << sweep;
  const std::filesystem::path table_md = dir / "tables" / "smoke_table3.md";
  sweep.replace(at, out_line.size(), "out: " + table_md.string());
  sweep += "overrides: [data.file=" + data + ", results_dir=" + results + "]\n";
  const Result s = run("sweep " + dir.write("smoke_table3.yaml", sweep).string());
  ASSERT_EQ(s.status, 0) << s.err;
  const std::string table = read_file(table_md);
  std::vector<double> avg_l1;
  for (const std::string experiment :
       {"smoke", "rignet_skin_smoke", "neuroskinning_smoke", "geo_voxel_smoke", "bone_heat_smoke"}) {
    EXPECT_TRUE(has_row(table, experiment, "smoke_table3"))
        << experiment << "\n" << table;
    const std::filesystem::path run_dir = std::filesystem::path(results) / experiment / "smoke_table3";
    const auto report = nlohmann::json::parse(read_file(run_dir / "eval_test.json"));
    EXPECT_EQ(report["per_character"].size(), 3u) << experiment;
    for (const char* key : {"precision", "recall", "avg_l1", "deformation_error"}) {
      const double value = report["mean"][key].get<double>();
      EXPECT_TRUE(std::isfinite(value)) << experiment << " " << key;
      EXPECT_GE(value, 0.0) << experiment << " " << key;
    }
    EXPECT_GT(report["mean"]["precision"].get<double>(), 0.0) << experiment;
    EXPECT_LE(report["mean"]["precision"].get<double>(), 1.0) << experiment;
    EXPECT_LE(report["mean"]["recall"].get<double>(), 1.0) << experiment;
    // Σ_b |P − G| of two distributions lies in [0, 2].
    EXPECT_LE(report["mean"]["avg_l1"].get<double>(), 2.0) << experiment;
    avg_l1.push_back(report["mean"]["avg_l1"].get<double>());
    const bool learned = experiment.find("voxel") == std::string::npos &&
                         experiment.find("heat") == std::string::npos;
    EXPECT_EQ(std::filesystem::exists(run_dir / "best.pt"), learned) << experiment;
    if (learned) {
      std::ifstream lines(run_dir / "metrics.jsonl");
      int epochs = 0;
      for (std::string line; std::getline(lines, line);) {
        const auto epoch = nlohmann::json::parse(line);
        EXPECT_TRUE(std::isfinite(epoch["train_loss"].get<double>())) << experiment;
        EXPECT_TRUE(std::isfinite(epoch["val_loss"].get<double>())) << experiment;
        ++epochs;
      }
      EXPECT_GE(epochs, 2) << experiment;
    }
  }
  // Five different methods give five different predictions.
  std::sort(avg_l1.begin(), avg_l1.end());
  EXPECT_EQ(std::adjacent_find(avg_l1.begin(), avg_l1.end()), avg_l1.end());
  EXPECT_NE(table.find("| One-way ANOVA vs smoke |"), std::string::npos) << table;
  EXPECT_NE(table.find("| bone_heat_smoke | "), std::string::npos) << table;
  // The same runs per skeleton family, read from the dataset file they were evaluated on.
  const std::string runs = results + "/smoke/smoke_table3 " + results + "/bone_heat_smoke/smoke_table3";
  const Result families = run("table " + runs + " --per family");
  ASSERT_EQ(families.status, 0) << families.err;
  EXPECT_NE(families.out.find("(each the mean over its characters; 3 characters) of the test part"),
            std::string::npos)
      << families.out;
  const Result unknown = run("table " + runs + " --per source");
  EXPECT_NE(unknown.status, 0);
  EXPECT_NE(unknown.err.find("--per"), std::string::npos) << unknown.err;
}

TEST(Cli, SmokeRunPrepareTrainEvalOnTheBundledSubset) {
  TempDir dir;
  const std::string data = (dir / "bundled.h5").string();
  const std::string results = (dir / "results").string();
  const Result p = run("prepare configs/datasets/zeroad_bundled.yaml output=" + data + " --threads 2");
  ASSERT_EQ(p.status, 0) << p.err;

  const Result t = run("train configs/smoke.yaml data.file=" + data + " results_dir=" + results +
                       " --run-id ci");
  ASSERT_EQ(t.status, 0) << t.err;
  const std::filesystem::path run_dir = dir / "results" / "smoke" / "ci";
  for (const char* f : {"config.yaml", "env.json", "metrics.jsonl", "best.pt", "last.pt"}) {
    EXPECT_TRUE(std::filesystem::exists(run_dir / f)) << f;
  }
  // Fixed seed: the validation loss (same characters every epoch, eval mode) goes down.
  std::ifstream lines(run_dir / "metrics.jsonl");
  std::vector<nlohmann::json> epochs;
  for (std::string line; std::getline(lines, line);) epochs.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(epochs.size(), 3u);
  EXPECT_LT(epochs.back()["val_loss"].get<double>(), epochs.front()["val_loss"].get<double>());
  EXPECT_EQ(epochs.front()["characters"].get<int>(), 4);

  const Result e = run("eval " + run_dir.string() + " --split test");
  ASSERT_EQ(e.status, 0) << e.err;
  const auto report = nlohmann::json::parse(read_file(run_dir / "eval_test.json"));
  const auto& m = report["mean"];
  for (const char* key : {"precision", "recall", "avg_l1", "deformation_error"}) {
    ASSERT_TRUE(m.contains(key)) << key << " missing in " << report.dump();
    EXPECT_TRUE(std::isfinite(m[key].get<double>())) << key;
  }
  EXPECT_GT(m["precision"].get<double>(), 0.0);
  EXPECT_LE(m["precision"].get<double>(), 1.0);
  EXPECT_GT(m["recall"].get<double>(), 0.0);
  EXPECT_LE(m["recall"].get<double>(), 1.0);

  // Predicted weights are valid: non-negative, rows sum to 1, non-zero only on the K candidates.
  const data::H5Reader h5(run_dir / "predictions" / "test.h5");
  const auto names = h5.read_strings("/character_names");
  ASSERT_FALSE(names.empty());
  for (const auto& name : names) {
    const std::string g = "/characters/" + name + "/";
    const data::RowMatrixXf candidates = h5.read_float(g + "candidates");
    const data::RowMatrixXf full = h5.read_float(g + "prepared_weights");
    const data::RowMatrixXi topk = h5.read_int(g + "topk_index");
    ASSERT_EQ(candidates.rows(), full.rows()) << name;
    EXPECT_GE(full.minCoeff(), 0.0f) << name;
    for (Eigen::Index v = 0; v < full.rows(); ++v) {
      ASSERT_NEAR(full.row(v).sum(), 1.0f, 1e-5f) << name << " vertex " << v;
      ASSERT_NEAR(candidates.row(v).sum(), 1.0f, 1e-5f) << name << " vertex " << v;
      int nonzero = 0;
      for (Eigen::Index b = 0; b < full.cols(); ++b) {
        if (full(v, b) == 0.0f) continue;
        ++nonzero;
        ASSERT_TRUE((topk.row(v).array() == static_cast<int>(b)).any())
            << name << " vertex " << v << " has weight on bone " << b << ", not a candidate";
      }
      ASSERT_LE(nonzero, topk.cols()) << name << " vertex " << v;
    }
  }

  // The checkpoint under an evaluation-only override as a run of its own (--run-id): its own
  // config, the same checkpoint and epoch, different weights; without overrides, an error and no
  // run.
  const Result d = run("eval " + run_dir.string() +
                       " experiment=smoke_leaf_bias model.leaf_bias=1.5 --run-id ci --split test");
  ASSERT_EQ(d.status, 0) << d.err;
  const std::filesystem::path derived = dir / "results" / "smoke_leaf_bias" / "ci";
  for (const char* f : {"config.yaml", "env.json", "metrics.jsonl", "best.pt", "eval_test.json"}) {
    EXPECT_TRUE(std::filesystem::exists(derived / f)) << f;
  }
  EXPECT_FALSE(std::filesystem::exists(derived / "last.pt"));
  EXPECT_NE(read_file(derived / "config.yaml").find("leaf_bias: 1.5"), std::string::npos);
  EXPECT_EQ(read_file(derived / "metrics.jsonl"), read_file(run_dir / "metrics.jsonl"));
  const auto biased = nlohmann::json::parse(read_file(derived / "eval_test.json"));
  EXPECT_EQ(biased["epoch"], report["epoch"]);
  EXPECT_NE(biased["mean"]["avg_l1"].get<double>(), m["avg_l1"].get<double>());
  const Result unchanged = run("eval " + run_dir.string() + " --run-id ci2");
  EXPECT_NE(unchanged.status, 0);
  EXPECT_NE(unchanged.err.find("none were given"), std::string::npos) << unchanged.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "results" / "smoke" / "ci2"));
  const Result wider = run("eval " + run_dir.string() + " model.head=[7] --run-id ci3");
  EXPECT_NE(wider.status, 0);
  EXPECT_NE(wider.err.find("best.pt"), std::string::npos) << wider.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "results" / "smoke" / "ci3"));

  // Error maps of the evaluated run: a PNG per map and a PLY per map, and per-vertex L1 values
  // whose mean is the evaluation's avg_l1 of that character (the README quotes it).
  const std::filesystem::path figures = dir / "figures";
  const Result f = run("figure " + run_dir.string() + " --count 1 --out " + figures.string());
  ASSERT_EQ(f.status, 0) << f.err;
  const auto& first = report["per_character"][0];
  const std::string character = first["character"].get<std::string>();
  for (const std::string& file : {character + "_l1.png", character + "_deformation.png",
                                 "smoke/" + character + "_l1.ply",
                                 "smoke/" + character + "_deformation.ply"}) {
    EXPECT_TRUE(std::filesystem::exists(figures / file)) << file << "\n" << f.out;
  }
  EXPECT_NE(read_file(figures / "README.md")
                .find(fmt::format("smoke {:.4f};", first["values"]["avg_l1"].get<double>())),
            std::string::npos)
      << read_file(figures / "README.md");
  const Result nf = run("figure " + run_dir.string() + " --part val --out " + figures.string());
  EXPECT_NE(nf.status, 0);
  EXPECT_NE(nf.err.find("no saved predictions for part 'val'"), std::string::npos) << nf.err;

  // A sweep of two entries (two seeds) trains, evaluates and tabulates both; run again, it only
  // re-reads the finished runs; a changed config under the same run directory is an error.
  // A sweep `name` of one-epoch smoke runs on the bundled subset, its table in tables/<name>.md;
  // `body` holds its runs (and `each`).
  const auto smoke_sweep = [&](const std::string& name, const std::string& body) {
    return dir.write(name + ".yaml", "name: " + name + "\nout: " +
                                         (dir / "tables" / (name + ".md")).string() +
                                         "\noverrides: [data.file=" + data + ", results_dir=" +
                                         results + ", train.epochs=1]\n" + body);
  };
  const auto sweep = smoke_sweep(
      "sw", "runs:\n  - configs/smoke.yaml\n"
            "  - {config: configs/smoke.yaml, overrides: [seed=1], run_id: sw-seed1}\n");
  const Result s1 = run("sweep " + sweep.string());
  ASSERT_EQ(s1.status, 0) << s1.err;
  const std::string table = read_file(dir / "tables" / "sw.md");
  EXPECT_TRUE(has_row(table, "smoke", "sw")) << table;
  EXPECT_TRUE(has_row(table, "smoke", "sw-seed1")) << table;
  EXPECT_TRUE(table.find("One-way ANOVA vs smoke (sw)") != std::string::npos ||
              table.find("One-way ANOVA vs smoke (sw†)") != std::string::npos)
      << table;
  EXPECT_TRUE(std::filesystem::exists(dir / "tables" / "sw.csv"));
  const Result s2 = run("sweep " + sweep.string());
  ASSERT_EQ(s2.status, 0) << s2.err;
  EXPECT_NE(s2.err.find("nothing to train"), std::string::npos) << s2.err;
  EXPECT_EQ(read_file(dir / "tables" / "sw.md"), table);
  const auto clash = dir.write(
      "clash.yaml", "name: sw\nout: x.md\noverrides: [data.file=" + data + ", results_dir=" +
                        results + ", train.epochs=2]\nruns: [configs/smoke.yaml]\n");
  const Result c = run("sweep " + clash.string());
  EXPECT_EQ(c.status, 1);
  EXPECT_NE(c.err.find("exists with another config"), std::string::npos) << c.err;
  const auto twice = dir.write("twice.yaml", "name: t\nout: x.md\nruns: [configs/smoke.yaml, "
                                             "configs/smoke.yaml]\n");
  const Result t2 = run("sweep " + twice.string());
  EXPECT_EQ(t2.status, 1);
  EXPECT_NE(t2.err.find("would share the run directory"), std::string::npos) << t2.err;
  // `each` runs every entry once per value, under the run id "<name>-<value>".
  const auto each =
      smoke_sweep("ea", "each: {override: 'seed={}', values: [3, 4]}\nruns: [configs/smoke.yaml]\n");
  const Result ea = run("sweep " + each.string());
  ASSERT_EQ(ea.status, 0) << ea.err;
  const std::string each_table = read_file(dir / "tables" / "ea.md");
  EXPECT_TRUE(has_row(each_table, "smoke", "ea-3")) << each_table;
  EXPECT_TRUE(has_row(each_table, "smoke", "ea-4")) << each_table;
  EXPECT_NE(read_file(std::filesystem::path(results) / "smoke" / "ea-4" / "config.yaml")
                .find("seed: 4\n"),
            std::string::npos);
  // --table-only trains nothing: the table of the entries already evaluated, the others named
  // under it as not yet run; with none evaluated it is an error.
  const auto overrides = "overrides: [data.file=" + data + ", results_dir=" + results +
                         ", train.epochs=1]\n";
  const auto partial = dir.write(
      "partial.yaml", "name: sw\nout: " + (dir / "tables" / "partial.md").string() + "\n" +
                          overrides + "runs:\n  - configs/smoke.yaml\n"
                          "  - {config: configs/smoke.yaml, overrides: [seed=2], run_id: sw-seed2}\n");
  const Result po = run("sweep " + partial.string() + " --table-only");
  ASSERT_EQ(po.status, 0) << po.err;
  const std::string partial_table = read_file(dir / "tables" / "partial.md");
  EXPECT_TRUE(has_row(partial_table, "smoke", "sw")) << partial_table;
  EXPECT_FALSE(has_row(partial_table, "smoke", "sw-seed2")) << partial_table;
  EXPECT_NE(partial_table.find("Not yet run or evaluated"), std::string::npos) << partial_table;
  EXPECT_NE(partial_table.find("sw-seed2`."), std::string::npos) << partial_table;
  EXPECT_NE(partial_table.find("--table-only"), std::string::npos) << partial_table;
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::path(results) / "smoke" / "sw-seed2"));
  // group_runs: the runs of one experiment (seeds) form one row.
  const auto grouped = dir.write(
      "grouped.yaml", "name: sw\nout: " + (dir / "tables" / "grouped.md").string() +
                          "\ngroup_runs: true\n" + overrides + "runs:\n  - configs/smoke.yaml\n"
                          "  - {config: configs/smoke.yaml, overrides: [seed=1], run_id: sw-seed1}\n");
  const Result gr = run("sweep " + grouped.string() + " --table-only");
  ASSERT_EQ(gr.status, 0) << gr.err;
  const std::string grouped_table = read_file(dir / "tables" / "grouped.md");
  const auto row = grouped_table.find("| smoke | sw");
  ASSERT_NE(row, std::string::npos) << grouped_table;
  const std::string line = grouped_table.substr(row, grouped_table.find('\n', row) - row);
  EXPECT_NE(line.find(", sw-seed1"), std::string::npos) << grouped_table;
  const auto none = dir.write("none.yaml", "name: none\nout: x.md\n" + overrides +
                                               "runs: [configs/smoke.yaml]\n");
  const Result no = run("sweep " + none.string() + " --table-only");
  EXPECT_EQ(no.status, 1);
  EXPECT_NE(no.err.find("no entry has been evaluated on the test part"), std::string::npos) << no.err;
  const auto bad_each = dir.write(
      "bad_each.yaml", "name: b\nout: x.md\neach: {override: 'seed=1', values: [3]}\n"
                       "runs: [configs/smoke.yaml]\n");
  const Result be = run("sweep " + bad_each.string());
  EXPECT_EQ(be.status, 1);
  EXPECT_NE(be.err.find("must contain {}"), std::string::npos) << be.err;

  check_smoke_table3(dir, data, results);
}


// What CI runs of DenseGATs' task: the bundled bipeds prepared, the smoke sweep of
// configs/sweeps/densegats_smoke_table3.yaml (a tiny DenseGATs trained, the LBS and DQS rows
// evaluated) through the binary, and its table.
TEST(Cli, DenseGatsSmokeSweepOnTheBundledBipeds) {
  TempDir dir;
  const std::string data = (dir / "bipeds.h5").string();
  const std::string results = (dir / "results").string();
  const Result p =
      run("prepare configs/datasets/zeroad_bipeds_bundled.yaml output=" + data + " --threads 2");
  ASSERT_EQ(p.status, 0) << p.err;
  std::string sweep = read_file(std::filesystem::path(SKINLAB_SOURCE_DIR) / "configs" / "sweeps" /
                                "densegats_smoke_table3.yaml");
  const std::string out_line = "out: results/tables/densegats_smoke_table3.md";
  ASSERT_NE(sweep.find(out_line), std::string::npos) << sweep;
  const std::filesystem::path table_md = dir / "table.md";
  sweep.replace(sweep.find(out_line), out_line.size(), "out: " + table_md.string());
  const std::string data_line = "data.file=results/datasets/zeroad_bipeds_bundled.h5";
  ASSERT_NE(sweep.find(data_line), std::string::npos) << sweep;
  sweep.replace(sweep.find(data_line), data_line.size(),
                "data.file=" + data + ", results_dir=" + results);
  const Result s = run("sweep " + dir.write("sweep.yaml", sweep).string());
  ASSERT_EQ(s.status, 0) << s.err;

  const std::string table = read_file(table_md);
  std::vector<double> means;
  for (const std::string experiment : {"densegats_smoke", "densegats_lbs", "densegats_dqs"}) {
    EXPECT_TRUE(has_row(table, experiment, "densegats_smoke_table3"))
        << experiment << "\n" << table;
    const auto report = nlohmann::json::parse(read_file(
        std::filesystem::path(results) / experiment / "densegats_smoke_table3" / "eval_test.json"));
    ASSERT_EQ(report["per_character"].size(), 1u) << experiment;
    EXPECT_EQ(report["task"], "corrective");
    const auto& m = report["mean"];
    EXPECT_EQ(m["poses"].get<double>(), 4.0) << experiment;
    EXPECT_GT(m["mean_error_cm"].get<double>(), 0.0) << experiment;
    EXPECT_LE(m["min_error_cm"].get<double>(), m["mean_error_cm"].get<double>()) << experiment;
    EXPECT_LE(m["mean_error_cm"].get<double>(), m["max_error_cm"].get<double>()) << experiment;
    means.push_back(m["mean_error_cm"].get<double>());
  }
  EXPECT_NE(means[1], means[2]);  // LBS and DQS differ
  EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(results) / "densegats_smoke" /
                                      "densegats_smoke_table3" / "best.pt"));
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::path(results) / "densegats_lbs" /
                                       "densegats_smoke_table3" / "best.pt"));
  EXPECT_NE(table.find("Metrics (the first run's evaluation): a vertex's error is its distance "
                       "to the Delta Mush target"),
            std::string::npos)
      << table;
  // A corrective config without a model or baseline cannot be evaluated, and says why.
  const Result e = run("eval configs/densegats/task.yaml data.file=" + data);
  EXPECT_NE(e.status, 0);

  // The error-colour figure (Fig. 10): ground truth, LBS, DQS and the network side by side.
  const std::filesystem::path lbs = std::filesystem::path(results) / "densegats_lbs" /
                                    "densegats_smoke_table3",
                              dqs = std::filesystem::path(results) / "densegats_dqs" /
                                    "densegats_smoke_table3",
                              net = std::filesystem::path(results) / "densegats_smoke" /
                                    "densegats_smoke_table3";
  const std::filesystem::path figures = dir / "figures";
  const Result f = run("figure " + lbs.string() + " " + dqs.string() + " " + net.string() +
                       " --poses 2 --out " + figures.string());
  ASSERT_EQ(f.status, 0) << f.err;
  const std::string caption = read_file(figures / "README.md");
  const std::string test_character = nlohmann::json::parse(read_file(net / "eval_test.json"))
                                         ["per_character"][0]["character"];
  std::size_t pngs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(figures)) {
    if (entry.path().extension() != ".png") continue;
    ++pngs;
    EXPECT_EQ(entry.path().filename().string().rfind(test_character + "_pose", 0), 0u)
        << entry.path();
    EXPECT_NE(caption.find("(" + entry.path().filename().string() + ")"), std::string::npos);
    for (const auto& experiment : {"densegats_lbs", "densegats_dqs", "densegats_smoke"}) {
      EXPECT_TRUE(std::filesystem::exists(figures / experiment /
                                          entry.path().filename().replace_extension(".ply")))
          << experiment << " " << entry.path();
    }
  }
  EXPECT_EQ(pngs, 2u) << caption;
  EXPECT_NE(caption.find("`densegats_dqs` (dqs, "), std::string::npos) << caption;
  // A run evaluated without predictions has nothing to draw, and the message says what to run.
  std::filesystem::remove_all(dqs / "predictions");
  const Result nf = run("figure " + lbs.string() + " " + dqs.string() + " --out " +
                        (dir / "figures2").string());
  EXPECT_NE(nf.status, 0);
  EXPECT_NE(nf.err.find("no saved predictions for part 'test'"), std::string::npos) << nf.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "figures2" / "README.md"));

  // Run again with its checkpoints, the finished network trains nothing and keeps its saved
  // evaluation byte for byte instead of being evaluated again.
  const std::string net_eval = read_file(net / "eval_test.json");
  const std::string net_env = read_file(net / "env.json");
  const Result finished = run("sweep " + (dir / "sweep.yaml").string());
  ASSERT_EQ(finished.status, 0) << finished.err;
  EXPECT_NE(finished.out.find("saved evaluation kept"), std::string::npos) << finished.out;
  EXPECT_EQ(read_file(net / "eval_test.json"), net_eval);
  EXPECT_EQ(read_file(net / "env.json"), net_env);
  // A committed run keeps its evaluation but not its checkpoints: the sweep uses the saved
  // evaluation instead of training it again; without that either, it refuses to retrain.
  for (const char* pt : {"best.pt", "last.pt"}) std::filesystem::remove(net / pt);
  const std::string before = read_file(net / "metrics.jsonl");
  const std::string lbs_eval = read_file(lbs / "eval_test.json");
  const Result again = run("sweep " + (dir / "sweep.yaml").string());
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_NE(again.out.find("saved evaluation; no checkpoint to resume"), std::string::npos)
      << again.out;
  // The untrained rows are not evaluated again either: their saved evaluation is their row.
  EXPECT_NE(again.out.find(lbs.string() + " (saved evaluation)"), std::string::npos) << again.out;
  EXPECT_EQ(read_file(lbs / "eval_test.json"), lbs_eval);
  EXPECT_EQ(read_file(net / "metrics.jsonl"), before);
  std::filesystem::remove(net / "eval_test.json");
  const Result gone = run("sweep " + (dir / "sweep.yaml").string());
  EXPECT_NE(gone.status, 0);
  EXPECT_NE(gone.err.find("has trained epochs (metrics.jsonl) but neither last.pt nor "
                          "eval_test.json"),
            std::string::npos)
      << gone.err;
  EXPECT_EQ(read_file(net / "metrics.jsonl"), before);
}

// What CI runs of the mesh-sequence task: the bundled sequences prepared, the smoke
// sweep of configs/sweeps/bdlstm_smoke_tables.yaml (a tiny share-weight BiLSTM and its
// unidirectional variant trained, ACAP extrapolation and the held frame evaluated) through the
// binary, its Tables 1-2, and the errors of evaluating what cannot be evaluated.
TEST(Cli, BdlstmSmokeSweepOnTheBundledWolf) {
  TempDir dir;
  const std::string data = (dir / "sequences.h5").string();
  const std::filesystem::path results = dir / "results";
  const Result p = run("prepare configs/datasets/zeroad_sequences_bundled.yaml output=" + data +
                       " --threads 2");
  ASSERT_EQ(p.status, 0) << p.err;
  std::string sweep = read_file(std::filesystem::path(SKINLAB_SOURCE_DIR) / "configs" / "sweeps" /
                                "bdlstm_smoke_tables.yaml");
  const std::string out_line = "out: results/tables/bdlstm_smoke_tables.md";
  ASSERT_NE(sweep.find(out_line), std::string::npos) << sweep;
  const std::filesystem::path table_md = dir / "table.md";
  sweep.replace(sweep.find(out_line), out_line.size(), "out: " + table_md.string());
  const std::string data_line = "data.file=results/datasets/zeroad_sequences_bundled.h5";
  ASSERT_NE(sweep.find(data_line), std::string::npos) << sweep;
  sweep.replace(sweep.find(data_line), data_line.size(),
                "data.file=" + data + ", results_dir=" + results.string());
  const Result s = run("sweep " + dir.write("sweep.yaml", sweep).string());
  ASSERT_EQ(s.status, 0) << s.err;

  const std::string table = read_file(table_md);
  for (const std::string row :
       {"| bdlstm_smoke (1 IF) |", "| bdlstm_smoke (3 IF) |", "| bdlstm_smoke_unidirectional (1 IF) |",
        "| bdlstm_acap_extrapolation (2 IF) |", "| bdlstm_hold (1 IF) |",
        "| bdlstm_smoke_mesh_vae (2 IF) |",
        "| ACAP floor (true features decoded) |", "| method | wolf 1st | wolf 5th |"}) {
    EXPECT_NE(table.find(row), std::string::npos) << row << "\n" << table;
  }
  const auto mean = [&](const std::string& experiment) {
    const auto report = nlohmann::json::parse(
        read_file(results / experiment / "bdlstm_smoke_tables" / "eval_test.json"));
    EXPECT_EQ(report["task"], "sequence");
    EXPECT_EQ(report["per_character"].size(), 1u);
    return report["mean"];
  };
  const auto net = mean("bdlstm_smoke"), hold = mean("bdlstm_hold"),
             extrapolation = mean("bdlstm_acap_extrapolation"), vae = mean("bdlstm_smoke_mesh_vae");
  EXPECT_EQ(vae["starts5"], hold["starts5"]);
  EXPECT_GT(vae["e5_2if_mm"].get<double>(), 0);
  EXPECT_TRUE(std::filesystem::exists(results / "bdlstm_smoke" / "bdlstm_smoke_tables" / "best.pt"));
  EXPECT_FALSE(std::filesystem::exists(results / "bdlstm_hold" / "bdlstm_smoke_tables" / "best.pt"));
  // Every method is scored on the same predictions; the floor does not depend on the method.
  EXPECT_EQ(net["starts5"], hold["starts5"]);
  EXPECT_GT(net["starts5"].get<double>(), 0);
  EXPECT_GE(net["starts1"].get<double>(), net["starts5"].get<double>());
  EXPECT_EQ(net["floor5_mm"], extrapolation["floor5_mm"]);
  // The wolf moves: 5 frames on, the held frame is further off than 1 frame on, and both are
  // above what the representation itself loses.
  EXPECT_GT(hold["e5_1if_mm"].get<double>(), hold["e1_1if_mm"].get<double>());
  EXPECT_GT(hold["e1_1if_mm"].get<double>(), hold["floor1_mm"].get<double>());
  for (const std::string key : {"e1_1if_mm", "e5_1if_mm", "e1_3if_mm", "e5_3if_mm"}) {
    EXPECT_GT(net[key].get<double>(), 0) << key;
  }
  // Nothing to evaluate, a part that is not held out, a baseline to train: clear errors.
  const Result e = run("eval configs/bdlstm/task.yaml experiment=none data.file=" + data);
  EXPECT_NE(e.status, 0);
  EXPECT_NE(e.err.find("'model' (trained first) or a 'sequences.baseline'"), std::string::npos) << e.err;
  const Result part = run("eval " + (results / "bdlstm_hold" / "bdlstm_smoke_tables").string() +
                          " --split train");
  EXPECT_NE(part.status, 0);
  EXPECT_NE(part.err.find("held-out windows"), std::string::npos) << part.err;
  const Result t = run("train configs/bdlstm/hold.yaml data.file=" + data);
  EXPECT_NE(t.status, 0);
  EXPECT_NE(t.err.find("is not trained"), std::string::npos) << t.err;

  // generate: the trained network continues a clip from its held-out window.
  const std::string smoke_run = (results / "bdlstm_smoke" / "bdlstm_smoke_tables").string();
  const std::filesystem::path seq = dir / "seq";
  const Result g = run("generate " + smoke_run + " --init-frames 3 --frames 4 --out " + seq.string());
  ASSERT_EQ(g.status, 0) << g.err;
  const auto info = nlohmann::json::parse(read_file(seq / "generate.json"));
  EXPECT_EQ(info["character"], "wolf");
  EXPECT_EQ(info["start"], info["held_out_window"][0]);
  ASSERT_EQ(info["frames"].size(), 4u);
  for (int t = 0; t < 7; ++t) {  // 3 given + 4 generated frames, each the wolf's mesh
    const geometry::Mesh frame = geometry::read_obj(seq / fmt::format("frame_{:04d}.obj", t));
    const geometry::Mesh first = geometry::read_obj(seq / "frame_0000.obj");
    EXPECT_EQ(frame.V.rows(), first.V.rows());
    EXPECT_EQ(frame.F, first.F);
  }
  EXPECT_FALSE(std::filesystem::exists(seq / "frame_0007.obj"));
  // Faces wound outwards, as viewers expect (the prepared wolf keeps 0 A.D.'s inward winding).
  const geometry::Mesh first = geometry::read_obj(seq / "frame_0000.obj");
  EXPECT_GT(testing::signed_volume(first.V, first.F), 0);
  // The initial frames are the clip's own frames.
  EXPECT_EQ(geometry::read_obj(seq / "frame_0002.obj").V, geometry::read_obj(seq / "truth_0002.obj").V);
  EXPECT_GT(info["frames"][0]["error_mm"].get<double>(), 0);
  EXPECT_TRUE(std::filesystem::exists(seq / "sequence.glb"));
  EXPECT_TRUE(std::filesystem::exists(seq / "truth.glb"));
  // An existing directory is not overwritten; a baseline run, a missing clip and initial frames
  // past the clip's end are clear errors.
  const std::string before = read_file(seq / "generate.json");
  const Result again = run("generate " + smoke_run + " --out " + seq.string());
  EXPECT_NE(again.status, 0);
  EXPECT_NE(again.err.find("exists"), std::string::npos) << again.err;
  EXPECT_EQ(read_file(seq / "generate.json"), before);
  const Result baseline = run("generate " + (results / "bdlstm_hold" / "bdlstm_smoke_tables").string() +
                              " --out " + (dir / "seq2").string());
  EXPECT_NE(baseline.status, 0);
  EXPECT_NE(baseline.err.find("baseline run (hold)"), std::string::npos) << baseline.err;
  const Result vae_run = run("generate " + (results / "bdlstm_smoke_mesh_vae" / "bdlstm_smoke_tables").string() +
                             " --out " + (dir / "seq2").string());
  EXPECT_NE(vae_run.status, 0);
  EXPECT_NE(vae_run.err.find("mesh_vae run extrapolates"), std::string::npos) << vae_run.err;
  const Result clip = run("generate " + smoke_run + " --clip nope --out " + (dir / "seq3").string());
  EXPECT_NE(clip.status, 0);
  EXPECT_NE(clip.err.find("no clip 'nope' (its clips: "), std::string::npos) << clip.err;
  const Result late = run("generate " + smoke_run + " --start 100000 --out " + (dir / "seq4").string());
  EXPECT_NE(late.status, 0);
  EXPECT_NE(late.err.find("do not fit"), std::string::npos) << late.err;
  for (const char* name : {"seq2", "seq3", "seq4"}) EXPECT_FALSE(std::filesystem::exists(dir / name));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

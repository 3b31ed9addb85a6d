#pragma once
// The files whose whole-file fuzzing tests/fuzz/h5_fuzz_test.cpp runs and whose reproducers
// tests/fuzz/h5_regressions_test.cpp replays (tests/data/fuzz_regressions/files/<target>/): for each
// target, seed files written by the project's own writers and the reader a command runs on it.
//
//   dataset      a dataset file (data/dataset_file.hpp, what train/eval read), two tiny
//                characters, contiguous and deflate-compressed seeds
//   predictions  an evaluation's predictions file (eval/predictions.hpp), read as `skinlab
//                figure` reads it
//   parameters   a small HeterSkinNet's parameters.h5 (infer/parameters.hpp), read and turned
//                into the Eigen network as `skinlab-predict` does
//   checkpoint   a training checkpoint with optimizer state (train/checkpoint.hpp), loaded as
//                `train --resume` does
//   model        a bundled model.pt (no optimizer state), loaded as `predict` does

#include <torch/torch.h>

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/data/h5.hpp"
#include "framework/eval/predictions.hpp"
#include "framework/infer/network.hpp"
#include "framework/infer/parameters.hpp"
#include "framework/predict/parameter_export.hpp"
#include "framework/train/checkpoint.hpp"
#include "framework/train/run_options.hpp"
#include "framework/train/trainer.hpp"
#include "tests/data/data_fixtures.hpp"

namespace skinlab::fuzz {

/// A small HeterSkinNet (every op type the Eigen pass has) for the parameter file and the
/// checkpoints.
inline const char* kSmallModel = R"(experiment: fuzz
seed: 3
model:
  type: heterskinnet
  top_k: 2
  stem:
    - {type: b2v, mlp: [4]}
    - {type: mesh_conv, edges: [one_ring, geodesic], edge_mlp: [4], mlp: [4]}
    - {type: edge_conv, edges: skeleton, mlp: [4]}
  local:
    - {type: v2b, mlp: [4]}
    - {type: global_pool, vertex_mlp: [4], bone_mlp: [], order: max_mlp, to: [vertex, bone]}
  global: {type: global_pool, pool: [vertex, bone], vertex_mlp: [4], bone_mlp: [4], to: [vertex]}
  head: [4]
losses: [{type: kl}]
data: {file: unused.h5, split: random, distance: euclidean}
)";

inline train::RunOptions small_model_options() {
  return train::RunOptions::from(config::Config::parse(kSmallModel));
}

struct FileTarget {
  std::string name;
  std::string extension;
  /// Writes the seed files into `dir` and returns their bytes.
  std::function<std::vector<std::string>(const std::filesystem::path& dir)> seeds;
  /// Reads `file` as the project does; throws skinlab::Error for a bad file.
  std::function<void(const std::filesystem::path& file)> parse;
};

inline data::Dataset tiny_fuzz_dataset() {
  data::Dataset d;
  d.characters = {testing::tiny_character("alpha"), testing::tiny_character("beta")};
  d.characters[1].leaf_tips = d.characters[1].joints;
  d.characters[1].augmented_from = "alpha";
  d.splits["random"] = {{0}, {}, {1}};
  d.excluded = {{"folder", "bad.fbx", "bad.fbx: cannot read"}};
  d.git_commit = "0123abcd";
  d.preparation = "preprocess: {}\ndistances: [{type: euclidean}]\n";
  return d;
}

/// Reads a predictions file the way report/error_maps.cpp and `skinlab figure` do.
inline void read_predictions(const std::filesystem::path& file) {
  const data::H5Reader r(file, "written by an older skinlab: run `skinlab eval` again");
  r.read_attribute("/", "distance");
  r.read_attribute("/", "split");
  r.read_int_attribute("/", "epoch");
  for (const std::string& name : r.read_strings("/character_names")) {
    const std::string g = "/characters/" + name + "/";
    if (!r.has(g + "prepared_weights")) throw IoError(file.string() + ": no " + g);
    r.read_float(g + "weights");
    r.read_float(g + "joint_weights");
    r.read_float(g + "prepared_weights");
    r.read_float(g + "candidates");
    r.read_int(g + "topk_index");
    r.read_int(g + "bones");
    r.read_strings(g + "joint_names");
    r.read_ints(g + "vertex_map");
  }
}

inline std::vector<FileTarget> file_targets() {
  namespace fs = std::filesystem;
  std::vector<FileTarget> targets;
  targets.push_back(
      {"dataset", ".h5",
       [](const fs::path& dir) {
         data::Dataset d = tiny_fuzz_dataset();
         data::write_dataset(dir / "raw.h5", d, /*deflate_level=*/0);
         data::AnimationData& clip = d.characters[0].animations.at(0);  // 1,080 values
         clip.num_frames = 30;
         clip.frames.resize(30 * 3 * 12, 0.25f);
         data::write_dataset(dir / "deflated.h5", d);  // the clip chunked and deflate-compressed
         return std::vector<std::string>{read_file(dir / "raw.h5"), read_file(dir / "deflated.h5")};
       },
       [](const fs::path& file) { data::read_dataset(file); }});
  targets.push_back(
      {"predictions", ".h5",
       [](const fs::path& dir) {
         const data::PreparedCharacter c = testing::tiny_character("alpha");
         eval::PredictionFile p(dir / "test.h5");
         torch::manual_seed(1);
         p.add(c, "euclidean", torch::rand({4, 2}), torch::rand({4, 4}),
               data::RowMatrixXf::Random(5, 4).cwiseAbs());
         p.set_attribute("distance", "euclidean");
         p.set_attribute("split", "random");
         p.set_attribute("epoch", std::int64_t{3});
         p.commit();
         return std::vector<std::string>{read_file(dir / "test.h5")};
       },
       read_predictions});
  targets.push_back(
      {"parameters", ".h5",
       [](const fs::path& dir) {
         const train::RunOptions options = small_model_options();
         const auto model = train::build_model(options);
         predict::write_parameter_file(dir / "parameters.h5", *model, options, "fuzz seed");
         return std::vector<std::string>{read_file(dir / "parameters.h5")};
       },
       [](const fs::path& file) {
         const infer::ParameterFile p = infer::read_parameter_file(file);
         infer::Network::from(p, file);
       }});
  for (const bool with_optimizer : {true, false}) {
    targets.push_back(
        {with_optimizer ? "checkpoint" : "model", ".pt",
         [with_optimizer](const fs::path& dir) {
           const auto model = train::build_model(small_model_options());
           torch::optim::Adam adam(model->parameters());
           for (auto& parameter : model->parameters()) {  // one step: Adam's state filled in
             parameter.mutable_grad() = torch::ones_like(parameter);
           }
           adam.step();
           train::TrainingState state;
           state.epoch = 2;
           state.best_epoch = 1;
           state.best_loss = 0.5;
           state.model_config = "type: heterskinnet\n";
           state.extra["plateau"] = 1;
           if (with_optimizer) {
             state.torch_rng = torch::rand({8});
             state.order_rng = torch::rand({8});
           }
           train::save_checkpoint(dir / "seed.pt", *model, with_optimizer ? &adam : nullptr,
                                  state);
           return std::vector<std::string>{read_file(dir / "seed.pt")};
         },
         [with_optimizer](const fs::path& file) {
           const auto model = train::build_model(small_model_options());
           torch::optim::Adam adam(model->parameters());
           train::load_checkpoint(file, *model, with_optimizer ? &adam : nullptr);
         }});
  }
  return targets;
}

}  // namespace skinlab::fuzz

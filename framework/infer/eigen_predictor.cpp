#include "framework/infer/eigen_predictor.hpp"

#include <fmt/format.h>

#include <chrono>

#include "framework/core/config.hpp"
#include "framework/core/error.hpp"
#include "framework/core/timing.hpp"
#include "framework/infer/model_dir.hpp"

namespace skinlab::infer {

namespace fs = std::filesystem;

data::RowMatrixXf forward(const Network& network, const data::PreparedCharacter& c,
                          const std::string& distance) {
  const auto it = c.distances.find(distance);
  if (it == c.distances.end()) {
    throw Error(fmt::format("{}: not prepared with distance '{}'", c.name, distance));
  }
  const data::DistanceData& d = it->second;
  const data::RowMatrixXd segments = c.rig().bone_segments();
  NetworkInput in;
  in.name = c.name;
  in.num_vertices = c.num_vertices();
  in.num_bones = c.num_bones();
  in.top_k = d.topk_index.cols();
  if (d.topk_index.rows() != c.num_vertices() || d.topk_distance.rows() != c.num_vertices() ||
      d.topk_distance.cols() != d.topk_index.cols() || c.V.cols() != 3 || c.bones.cols() != 2 ||
      segments.rows() != c.num_bones() || segments.cols() != 6 ||
      (c.one_ring_edges.size() > 0 && c.one_ring_edges.cols() != 2) ||
      (c.geodesic_edges.size() > 0 && c.geodesic_edges.cols() != 2)) {
    throw Error(fmt::format("{}: the prepared arrays do not have the shapes of #V = {} vertices "
                            "and #B = {} bones",
                            c.name, c.num_vertices(), c.num_bones()));
  }
  in.positions = c.V.data();
  in.topk_distance = d.topk_distance.data();
  in.topk_index = d.topk_index.data();
  in.one_ring = c.one_ring_edges.data();
  in.num_one_ring = c.one_ring_edges.rows();
  in.geodesic = c.geodesic_edges.data();
  in.num_geodesic = c.geodesic_edges.rows();
  in.bones = c.bones.data();
  in.bone_segments = segments.data();
  data::RowMatrixXf prior;  // #V×K: the prior's weight on each candidate (as CharacterTensors::priors)
  if (!network.prior().empty()) {
    const auto p = c.priors.find(network.prior());
    if (p == c.priors.end()) {
      throw Error(fmt::format("{}: the model reads the '{}' prior, which its preparation did "
                              "not compute (preprocess.priors)",
                              c.name, network.prior()));
    }
    if (p->second.rows() != c.num_vertices() || p->second.cols() != c.num_bones()) {
      throw Error(fmt::format("{}: the '{}' prior is {}×{}, not #V×#B = {}×{}", c.name,
                              network.prior(), p->second.rows(), p->second.cols(),
                              c.num_vertices(), c.num_bones()));
    }
    prior.resize(in.num_vertices, in.top_k);
    for (Eigen::Index v = 0; v < prior.rows(); ++v) {
      for (Eigen::Index j = 0; j < prior.cols(); ++j) {
        const int b = d.topk_index(v, j);
        prior(v, j) = b >= 0 && b < c.num_bones() ? p->second(v, b) : 0.0f;
      }
    }
    in.prior = prior.data();
  }
  const std::vector<float> out = network.forward(in);
  return Eigen::Map<const data::RowMatrixXf>(out.data(), in.num_vertices, in.top_k);
}

EigenPredictor::EigenPredictor(Network network, Preparation preparation, std::string distance,
                               std::string description)
    : network_(std::move(network)),
      preparation_(std::move(preparation)),
      distance_(std::move(distance)),
      description_(std::move(description)) {}

EigenPredictor EigenPredictor::load(const fs::path& dir) {
  if (!fs::is_directory(dir)) {
    throw IoError(dir.string() + ": not a model directory; give a bundled model "
                                 "(results/bundled/<name>)");
  }
  const fs::path file = dir / "parameters.h5";
  if (!fs::exists(file)) {
    throw IoError(file.string() + ": missing; skinlab-predict runs the parameter file that "
                                  "skinlab bundle writes (skinlab export-parameters DIR adds it "
                                  "to an older bundle or a run)");
  }
  const ParameterFile parameters = read_parameter_file(file);
  Network network = Network::from(parameters, file);
  std::string data_file;
  const fs::path config_file = dir / "config.yaml";
  if (!fs::exists(dir / "preparation.yaml") && fs::exists(config_file)) {
    const config::Node data = config::Config::load(config_file).root()["data"]["file"];
    if (data.exists()) data_file = data.as<std::string>();
  }
  Preparation preparation = load_preparation(dir, data_file, parameters.distance, network.prior());
  if (preparation.preprocess.top_k != network.top_k()) {
    throw ConfigError(fmt::format("{}: the preparation picks {} candidate bones per vertex, but "
                                  "the network of {} takes K = {}",
                                  dir.string(), preparation.preprocess.top_k, file.string(),
                                  network.top_k()));
  }
  return EigenPredictor(std::move(network), std::move(preparation), parameters.distance,
                        fmt::format("{} (parameters.h5: {})", dir.string(), parameters.source));
}

Prediction EigenPredictor::predict(const geometry::Character& character,
                                   const PredictOptions& options, StageTimes* times) const {
  PreparedInput input = prepare_to_predict(character, preparation_, options, times);
  const auto start = std::chrono::steady_clock::now();
  data::RowMatrixXf candidates = forward(network_, input.prepared, distance_);
  if (times != nullptr) times->network += seconds_since(start);
  const PriorUse prior{network_.prior(), network_.keep_prior_outside(), network_.prior_mix()};
  return finish_prediction(std::move(input), distance_, std::move(candidates), options.prune,
                           prior, times);
}

}  // namespace skinlab::infer

#pragma once
/// \file
/// A trained network's parameters in a plain, documented format (docs/parameters.md), written
/// by `skinlab bundle` and `skinlab export-parameters` from the libtorch model and read by the
/// Eigen forward pass of `skinlab-predict` (infer/network.hpp) without libtorch. One HDF5 file:
///
///     /                      attributes
///         format             "skinlab-parameters"
///         format_version     2 (1 stored its strings variable-length; refused: re-export)
///         model              the config's model type, e.g. "heterskinnet"
///         distance           the distance registry key the model reads, e.g. "hollow_dist"
///         source             where the parameters come from: "<run> (best.pt, epoch 35)"
///         architecture       JSON text: the model's options and its modules (below)
///     /parameters/<path>     one float32 dataset per parameter, named by its libtorch
///                            parameter path (e.g. "stem.0_b2v.mlp.linear0.weight"); a Linear
///                            layer's weight is out×in (row-major, y = W x + b), its bias 1-D
///
/// `architecture` holds what the parameters alone do not say: `top_k`, `distance_unit` and
/// `min_distance` of the model (HeterSkinNet's 1/D input, models/branched_model.hpp); the op
/// lists `stem` and `local` (each op: its module name, `type` and options, e.g.
/// `{"name": "0_b2v", "type": "b2v", "mlp": [256]}`) and the op `global_branch`; and `mlps`,
/// every MLP of the model by module path with its input width, layer widths and whether its
/// last layer is activated (LeakyReLU(0.2) after every other layer, HeterSkinNet Sec. 4.2).
/// The string attributes are fixed-length (data/h5.hpp: no variable-length data, so no damaged
/// file reaches HDF5's global heap).

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace skinlab::infer {

inline constexpr const char* kParameterFormat = "skinlab-parameters";
inline constexpr int kParameterFormatVersion = 2;

/// One parameter: its shape and its float32 values in row-major order.
struct ParameterArray {
  std::vector<std::size_t> shape;
  std::vector<float> values;
};

struct ParameterFile {
  std::string model;     ///< the config's model type
  std::string distance;  ///< the distance the model reads
  std::string source;    ///< provenance, free text
  nlohmann::json architecture = nlohmann::json::object();
  std::map<std::string, ParameterArray> parameters;  ///< by libtorch parameter path
};

/// Writes `p` to `file` through a temporary file renamed into place (no partial file under the
/// final name). Error for a parameter whose values do not fill its shape.
void write_parameter_file(const std::filesystem::path& file, const ParameterFile& p);

/// Reads `file`. IoError naming the file and the element for: a missing file, not HDF5, a
/// missing or unknown `format`, a `format_version` this build does not read, a missing
/// attribute, an `architecture` that is not a JSON object, and a parameter that is not float
/// or holds a non-finite value (the parameter and the index named).
ParameterFile read_parameter_file(const std::filesystem::path& file);

}  // namespace skinlab::infer

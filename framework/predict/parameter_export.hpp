#pragma once
/// \file
/// A libtorch model's parameters and architecture in the plain format of infer/parameters.hpp
/// (docs/parameters.md), so `skinlab-predict` can run it with Eigen. Written by `skinlab
/// bundle` beside model.pt and by `skinlab export-parameters`.
///
/// The architecture is read off the built modules, not re-derived from the config: every
/// direct submodule of the model that is a graph-op list (graph::Sequence: `stem`, `local`) is
/// written as the list of its ops, one that is a single op (`global_branch`) as that op, each
/// op with its module name, registry type and the options the forward pass needs
/// (graph/b2v.hpp, v2b.hpp, edge_conv.hpp, mesh_conv.hpp, global_pool.hpp); an op of another
/// type is written with its type only, which the Eigen side refuses by name. Every MLP of the
/// model (graph/mlp.hpp) is listed under `mlps` by module path with its input width, widths and
/// last activation. `top_k`, `distance_unit` and `min_distance` are the model's options
/// (models/branched_model.hpp: HeterSkinNet's K and 1/D input, Sec. 3.2 and 4.2); a model
/// reading a prior adds `prior`, `prior_bias`, `prior_epsilon` and `keep_prior_outside`, and
/// `prior_mix` when it is not 0 (models::PriorOptions).

#include <filesystem>
#include <string>

#include "framework/infer/parameters.hpp"
#include "framework/models/branched_model.hpp"
#include "framework/models/model.hpp"
#include "framework/train/run_options.hpp"

namespace skinlab::predict {


/// The parameter file of `model` (built from `run`'s config); `source` is its provenance.
infer::ParameterFile parameter_file(const models::Model& model, const train::RunOptions& run,
                                    const std::string& source);

/// parameter_file(...) written to `file` atomically (infer::write_parameter_file).
void write_parameter_file(const std::filesystem::path& file, const models::Model& model,
                          const train::RunOptions& run, const std::string& source);

}  // namespace skinlab::predict

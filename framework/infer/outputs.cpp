#include "framework/infer/outputs.hpp"

#include <fmt/format.h>

#include <vector>

#include "framework/core/error.hpp"
#include "framework/data/h5.hpp"
#include "framework/geometry/gltf_export.hpp"
#include "framework/geometry/rig_io.hpp"
#include "framework/geometry/vertex_normals.hpp"
#include "framework/infer/map_back.hpp"

namespace skinlab::infer {

namespace fs = std::filesystem;

namespace {

void write_h5(const fs::path& out, const geometry::Character& input, const Prediction& p,
              const std::string& model, const std::string& distance, double prune) {
  data::H5Writer w(out);
  w.write("weights", p.source_weights);
  w.write("joint_weights", data::RowMatrixXd(Eigen::MatrixXd(p.joint_weights)));
  // the bones' joints as the input's joint indices (the prepared skeleton may leave helper ends out)
  data::RowMatrixXi bones = p.prepared.bones;
  for (Eigen::Index i = 0; i < bones.size(); ++i) {
    bones.data()[i] = p.input_joints[static_cast<std::size_t>(bones.data()[i])];
  }
  w.write("bones", bones);
  w.write_strings("joint_names", input.skeleton.names);
  w.write("vertices", data::RowMatrixXd(input.mesh.V));
  w.write_attribute("model", model);
  w.write_attribute("distance", distance);
  w.write_attribute("prune", fmt::format("{}", prune));
  w.write_attribute("character", input.name);
  w.commit();
}

}  // namespace

OutputKind output_kind(const fs::path& out) {
  const std::string ext = out.extension().string();
  if (ext == ".glb" || ext == ".gltf") return OutputKind::gltf;
  if (ext == ".h5" || ext == ".hdf5") return OutputKind::h5;
  if (ext == ".txt") return OutputKind::rig;
  throw Error(out.string() + ": unknown output type '" + ext +
              "' (use .glb, .gltf, _rig.txt or .h5)");
}

void write_prediction(const fs::path& out, const geometry::Character& input, const Prediction& p,
                      const std::string& model, const std::string& distance, double prune) {
  geometry::Character result;
  result.name = input.name;
  result.mesh = input.mesh;
  result.skeleton = input.skeleton;
  result.weights = p.joint_weights;
  switch (output_kind(out)) {
    case OutputKind::gltf: {
      geometry::GltfExportOptions gltf;
      gltf.normals = geometry::vertex_normals(input.mesh);
      geometry::write_gltf(out, result, gltf);
      break;
    }
    case OutputKind::rig: {
      // Every joint of the input, the left-out helper ends too (with no weight).
      geometry::Skeleton named;
      named.names = rig_joint_names(input.skeleton.names);
      named.parents = input.skeleton.parents;
      named.positions = input.skeleton.positions;
      geometry::write_rig(out, named, p.joint_weights);
      break;
    }
    case OutputKind::h5:
      write_h5(out, input, p, model, distance, prune);
      break;
  }
}

OtherWeights read_other_weights(const fs::path& file, const geometry::Character& truth,
                                const std::string& truth_name, bool allow_unweighted) {
  geometry::Skeleton other_skeleton;
  geometry::SparseWeights other;
  if (file.extension() == ".txt") {
    geometry::WeightCheck check;
    check.allow_unweighted = allow_unweighted;
    geometry::Rig r = geometry::read_rig(file, truth.mesh.num_vertices(), check);
    other_skeleton = r.skeleton;
    other = r.weights;
  } else {
    geometry::Character c = geometry::load_character(file);
    if (c.mesh.num_vertices() != truth.mesh.num_vertices()) {
      throw Error(fmt::format("{}: {} vertices, but {} has {}", file.string(), c.mesh.num_vertices(),
                              truth_name, truth.mesh.num_vertices()));
    }
    other_skeleton = c.skeleton;
    other = c.weights;
  }
  // A method that weighted no vertex at all (Blender's bone heat when it finds no solution for
  // any bone) writes no skin line: with allow_unweighted every vertex predicts no bone.
  if (other.rows() == 0 && allow_unweighted) {
    other.resize(truth.mesh.num_vertices(), other_skeleton.num_joints());
  }
  if (other.rows() != truth.mesh.num_vertices()) {
    throw Error(file.string() + ": no weights for the " + std::to_string(truth.mesh.num_vertices()) +
                " vertices of " + truth_name);
  }
  // Columns by joint name onto the truth's skeleton.
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index v = 0; v < other.outerSize(); ++v) {
    for (geometry::SparseWeights::InnerIterator it(other, v); it; ++it) {
      const std::string& name = other_skeleton.names[static_cast<std::size_t>(it.col())];
      const int j = truth.skeleton.find(name);
      if (j < 0) throw Error(file.string() + ": joint '" + name + "' is not a joint of " + truth_name);
      entries.emplace_back(static_cast<int>(v), j, it.value());
    }
  }
  geometry::SparseWeights mapped(truth.mesh.num_vertices(), truth.skeleton.num_joints());
  mapped.setFromTriplets(entries.begin(), entries.end());
  int unweighted = 0;
  for (Eigen::Index v = 0; v < mapped.rows(); ++v) {
    if (!(mapped.row(v).sum() > 0)) {
      if (!allow_unweighted) {
        throw Error(fmt::format("{}: vertex {} has no weight (--allow-unweighted scores it as "
                                "predicting no bone)",
                                file.string(), v));
      }
      ++unweighted;
      continue;
    }
    mapped.row(v) /= mapped.row(v).sum();
  }
  return {mapped, unweighted};
}

}  // namespace skinlab::infer

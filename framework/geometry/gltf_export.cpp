#include "framework/geometry/gltf_export.hpp"

#include <tiny_gltf.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/core/error.hpp"

namespace skinlab::geometry {

namespace {

/// Appends `bytes` to buffer 0 as a new buffer view (4-byte aligned, as accessors of 4-byte
/// components need) and an accessor over it; returns the accessor index.
int add_accessor(tinygltf::Model& model, const void* data, std::size_t bytes, int component_type,
                 int type, std::size_t count, int target) {
  auto& buffer = model.buffers[0].data;
  while (buffer.size() % 4 != 0) buffer.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  view.byteLength = bytes;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(data);
  buffer.insert(buffer.end(), p, p + bytes);
  model.bufferViews.push_back(view);

  tinygltf::Accessor accessor;
  accessor.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
  accessor.componentType = component_type;
  accessor.type = type;
  accessor.count = count;
  model.accessors.push_back(accessor);
  return static_cast<int>(model.accessors.size()) - 1;
}

/// The kept influences of every vertex: the largest `max_influences` weights of its row of W
/// (#V×#J), renormalised, as (joint, weight) pairs, largest first.
std::vector<std::vector<std::pair<int, float>>> kept_influences(const SparseWeights& W,
                                                                 int max_influences,
                                                                 const std::string& where) {
  std::vector<std::vector<std::pair<int, float>>> out(static_cast<std::size_t>(W.rows()));
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    std::vector<std::pair<int, double>> row;
    for (SparseWeights::InnerIterator it(W, v); it; ++it) {
      if (it.value() > 0) row.emplace_back(static_cast<int>(it.col()), it.value());
    }
    if (row.empty()) throw Error(where + ": vertex " + std::to_string(v) + " has no weight");
    std::sort(row.begin(), row.end(), [](const auto& a, const auto& b) {
      return a.second != b.second ? a.second > b.second : a.first < b.first;
    });
    if (static_cast<int>(row.size()) > max_influences) row.resize(max_influences);
    double sum = 0;
    for (const auto& [j, w] : row) sum += w;
    auto& kept = out[static_cast<std::size_t>(v)];
    for (const auto& [j, w] : row) kept.emplace_back(j, static_cast<float>(w / sum));
  }
  return out;
}

/// A float32 VEC3 accessor over the rows of P (#P×3), in buffer 0; with `bounds`, its min/max
/// (which the specification requires of POSITION accessors, morph targets included).
int add_vec3_accessor(tinygltf::Model& model, const Eigen::MatrixXd& P, bool bounds) {
  const auto n = static_cast<std::size_t>(P.rows());
  std::vector<float> values(n * 3);
  std::vector<double> lo(3, std::numeric_limits<double>::infinity());
  std::vector<double> hi(3, -std::numeric_limits<double>::infinity());
  for (std::size_t v = 0; v < n; ++v) {
    for (int a = 0; a < 3; ++a) {
      const float x = static_cast<float>(P(static_cast<Eigen::Index>(v), a));
      values[v * 3 + a] = x;
      lo[a] = std::min(lo[a], static_cast<double>(x));
      hi[a] = std::max(hi[a], static_cast<double>(x));
    }
  }
  const int accessor = add_accessor(model, values.data(), values.size() * sizeof(float),
                                    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n,
                                    TINYGLTF_TARGET_ARRAY_BUFFER);
  if (bounds) {
    model.accessors[accessor].minValues = lo;
    model.accessors[accessor].maxValues = hi;
  }
  return accessor;
}

/// A triangle primitive with POSITION V (#V×3) and unsigned 32-bit indices F (#F×3).
tinygltf::Primitive triangle_primitive(tinygltf::Model& model, const Eigen::MatrixXd& V,
                                       const Eigen::MatrixXi& F) {
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.attributes["POSITION"] = add_vec3_accessor(model, V, true);
  std::vector<std::uint32_t> indices(static_cast<std::size_t>(F.rows()) * 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      indices[static_cast<std::size_t>(f) * 3 + c] = static_cast<std::uint32_t>(F(f, c));
    }
  }
  primitive.indices = add_accessor(model, indices.data(), indices.size() * sizeof(std::uint32_t),
                                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                                   indices.size(), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  return primitive;
}

/// Serialises `model` to `file` (.glb binary, .gltf JSON with an embedded buffer), atomically.
void write_model(const std::filesystem::path& file, tinygltf::Model& model) {
  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  const bool binary = file.extension() == ".glb";
  if (!writer.WriteGltfSceneToStream(&model, stream, /*prettyPrint=*/!binary, binary)) {
    throw IoError(file.string() + ": TinyGLTF could not serialise the asset");
  }
  write_file_atomic(file, stream.str());
}

/// Throws Error naming `file` unless it ends in .glb or .gltf.
void check_gltf_extension(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  if (ext != ".glb" && ext != ".gltf") {
    throw Error(file.string() + ": unknown glTF extension '" + ext + "' (use .glb or .gltf)");
  }
}

}  // namespace

void write_gltf(const std::filesystem::path& file, const Character& character,
                const GltfExportOptions& options) {
  const std::string where = file.string();
  check_gltf_extension(file);
  if (options.max_influences < 1 || options.max_influences > 8) {
    throw Error(where + ": max_influences must be in 1..8, got " +
                std::to_string(options.max_influences));
  }
  const Mesh& mesh = character.mesh;
  const Skeleton& skeleton = character.skeleton;
  const int nv = mesh.num_vertices();
  const int nj = skeleton.num_joints();
  if (!character.has_weights()) {
    throw Error(where + ": character '" + character.name + "' has no weights");
  }
  if (character.weights.rows() != nv || character.weights.cols() != nj) {
    throw Error(where + ": weights are " + std::to_string(character.weights.rows()) + "×" +
                std::to_string(character.weights.cols()) + ", expected #V×#J = " +
                std::to_string(nv) + "×" + std::to_string(nj));
  }
  if (options.normals.rows() != 0 && options.normals.rows() != nv) {
    throw Error(where + ": " + std::to_string(options.normals.rows()) + " normals for " +
                std::to_string(nv) + " vertices");
  }

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "skinlab";
  model.buffers.emplace_back();

  // Joints: node j is joint j, its +Y turned towards its children (see the header).
  const auto children = skeleton.children();
  std::vector<Eigen::Matrix3d> rotation(static_cast<std::size_t>(nj));
  std::vector<int> parents_first{skeleton.root()};
  for (std::size_t i = 0; i < parents_first.size(); ++i) {
    for (int c : children[parents_first[i]]) parents_first.push_back(c);
  }
  for (int j : parents_first) {
    const int p = skeleton.parents[j];
    Eigen::Vector3d towards = Eigen::Vector3d::Zero();
    for (int c : children[j]) {
      towards += (skeleton.positions.row(c) - skeleton.positions.row(j)).transpose();
    }
    const Eigen::Matrix3d inherited =
        p < 0 ? Eigen::Matrix3d::Identity() : rotation[static_cast<std::size_t>(p)];
    rotation[static_cast<std::size_t>(j)] =
        towards.norm() > 1e-9 * (1.0 + skeleton.positions.row(j).norm())
            ? Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitY(), towards)
                  .toRotationMatrix()
            : inherited;
  }
  for (int j = 0; j < nj; ++j) {
    tinygltf::Node node;
    node.name = skeleton.names[j];
    const int p = skeleton.parents[j];
    const Eigen::Matrix3d& r = rotation[static_cast<std::size_t>(j)];
    const Eigen::Vector3d position = skeleton.positions.row(j).transpose();
    Eigen::Vector3d local = position;
    Eigen::Matrix3d local_rotation = r;
    if (p >= 0) {
      const Eigen::Matrix3d& rp = rotation[static_cast<std::size_t>(p)];
      local = rp.transpose() * (position - skeleton.positions.row(p).transpose());
      local_rotation = rp.transpose() * r;
    }
    node.translation = {local.x(), local.y(), local.z()};
    const Eigen::Quaterniond q(local_rotation);
    if (!local_rotation.isIdentity(1e-12)) node.rotation = {q.x(), q.y(), q.z(), q.w()};
    node.children.assign(children[j].begin(), children[j].end());
    model.nodes.push_back(std::move(node));
  }

  // Geometry.
  tinygltf::Primitive primitive = triangle_primitive(model, mesh.V, mesh.F);
  if (options.normals.rows() == nv) {
    primitive.attributes["NORMAL"] = add_vec3_accessor(model, options.normals, false);
  }

  // Weights, four influences per set.
  const auto kept = kept_influences(character.weights, options.max_influences, where);
  std::size_t most = 0;
  for (const auto& k : kept) most = std::max(most, k.size());
  const int sets = static_cast<int>((most + 3) / 4);
  const bool wide = nj > 256;
  for (int s = 0; s < sets; ++s) {
    std::vector<std::uint16_t> joints16(static_cast<std::size_t>(nv) * 4, 0);
    std::vector<std::uint8_t> joints8(static_cast<std::size_t>(nv) * 4, 0);
    std::vector<float> weights(static_cast<std::size_t>(nv) * 4, 0.0f);
    for (int v = 0; v < nv; ++v) {
      const auto& k = kept[static_cast<std::size_t>(v)];
      for (int i = 0; i < 4; ++i) {
        const std::size_t at = static_cast<std::size_t>(s) * 4 + i;
        if (at >= k.size()) break;
        const std::size_t slot = static_cast<std::size_t>(v) * 4 + i;
        joints16[slot] = static_cast<std::uint16_t>(k[at].first);
        joints8[slot] = static_cast<std::uint8_t>(k[at].first);
        weights[slot] = k[at].second;
      }
    }
    const std::string n = std::to_string(s);
    primitive.attributes["JOINTS_" + n] =
        wide ? add_accessor(model, joints16.data(), joints16.size() * 2,
                            TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC4, nv,
                            TINYGLTF_TARGET_ARRAY_BUFFER)
             : add_accessor(model, joints8.data(), joints8.size(),
                            TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_VEC4, nv,
                            TINYGLTF_TARGET_ARRAY_BUFFER);
    primitive.attributes["WEIGHTS_" + n] =
        add_accessor(model, weights.data(), weights.size() * sizeof(float),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, nv,
                     TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  tinygltf::Mesh gltf_mesh;
  gltf_mesh.name = character.name;
  gltf_mesh.primitives.push_back(std::move(primitive));
  model.meshes.push_back(std::move(gltf_mesh));

  // Skin: inverse bind matrices G_j⁻¹ = [R_jᵀ | −R_jᵀ p_j], column-major.
  std::vector<float> ibm(static_cast<std::size_t>(nj) * 16, 0.0f);
  tinygltf::Skin skin;
  skin.name = character.name + "_skin";
  skin.skeleton = skeleton.root();
  for (int j = 0; j < nj; ++j) {
    const Eigen::Matrix3d rt = rotation[static_cast<std::size_t>(j)].transpose();
    const Eigen::Vector3d t = -rt * skeleton.positions.row(j).transpose();
    float* m = ibm.data() + static_cast<std::size_t>(j) * 16;
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) m[c * 4 + r] = static_cast<float>(rt(r, c));
      m[12 + c] = static_cast<float>(t(c));
    }
    m[15] = 1.0f;
    skin.joints.push_back(j);
  }
  skin.inverseBindMatrices =
      add_accessor(model, ibm.data(), ibm.size() * sizeof(float), TINYGLTF_COMPONENT_TYPE_FLOAT,
                   TINYGLTF_TYPE_MAT4, nj, /*target: none*/ 0);
  model.skins.push_back(std::move(skin));

  tinygltf::Node mesh_node;
  mesh_node.name = character.name;
  mesh_node.mesh = 0;
  mesh_node.skin = 0;
  model.nodes.push_back(std::move(mesh_node));

  tinygltf::Scene scene;
  scene.name = character.name;
  scene.nodes = {skeleton.root(), nj};
  model.scenes.push_back(std::move(scene));
  model.defaultScene = 0;

  write_model(file, model);
}

void write_gltf_morph_animation(const std::filesystem::path& file, const std::string& name,
                                const Eigen::MatrixXi& F, const std::vector<Eigen::MatrixXd>& frames,
                                double fps) {
  const std::string where = file.string();
  check_gltf_extension(file);
  if (frames.empty()) throw Error(where + ": no frame to write");
  if (!(fps > 0) || !std::isfinite(fps)) {
    throw Error(where + ": frames per second must be positive, got " + std::to_string(fps));
  }
  const Eigen::MatrixXd& base = frames.front();
  for (std::size_t t = 0; t < frames.size(); ++t) {
    if (frames[t].rows() != base.rows() || frames[t].cols() != 3) {
      throw Error(where + ": frame " + std::to_string(t) + " is " + std::to_string(frames[t].rows()) +
                  "×" + std::to_string(frames[t].cols()) + ", expected " +
                  std::to_string(base.rows()) + "×3 like frame 0");
    }
    if (!frames[t].allFinite()) {
      throw Error(where + ": frame " + std::to_string(t) + " has a non-finite coordinate");
    }
  }
  if (F.size() > 0 && (F.minCoeff() < 0 || F.maxCoeff() >= base.rows())) {
    throw Error(where + ": a face index is outside 0.." + std::to_string(base.rows() - 1));
  }

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "skinlab";
  model.buffers.emplace_back();
  tinygltf::Primitive primitive = triangle_primitive(model, base, F);
  const std::size_t targets = frames.size() - 1;
  for (std::size_t t = 1; t < frames.size(); ++t) {
    primitive.targets.push_back({{"POSITION", add_vec3_accessor(model, frames[t] - base, true)}});
  }
  tinygltf::Mesh mesh;
  mesh.name = name;
  mesh.primitives.push_back(std::move(primitive));
  mesh.weights.assign(targets, 0.0);
  model.meshes.push_back(std::move(mesh));
  tinygltf::Node node;
  node.name = name;
  node.mesh = 0;
  model.nodes.push_back(std::move(node));
  tinygltf::Scene scene;
  scene.name = name;
  scene.nodes = {0};
  model.scenes.push_back(std::move(scene));
  model.defaultScene = 0;

  if (targets > 0) {
    // Keyframe k (time k / fps) shows frame k: target k − 1 at weight 1, every other at 0.
    std::vector<float> times(frames.size());
    std::vector<float> weights(frames.size() * targets, 0.0f);
    for (std::size_t k = 0; k < frames.size(); ++k) {
      times[k] = static_cast<float>(static_cast<double>(k) / fps);
      if (k > 0) weights[k * targets + (k - 1)] = 1.0f;
    }
    const int input = add_accessor(model, times.data(), times.size() * sizeof(float),
                                   TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR,
                                   times.size(), /*target: none*/ 0);
    model.accessors[input].minValues = {times.front()};
    model.accessors[input].maxValues = {times.back()};
    const int output = add_accessor(model, weights.data(), weights.size() * sizeof(float),
                                    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR,
                                    weights.size(), /*target: none*/ 0);
    tinygltf::Animation animation;
    animation.name = name;
    tinygltf::AnimationSampler sampler;
    sampler.input = input;
    sampler.output = output;
    sampler.interpolation = "LINEAR";
    animation.samplers.push_back(sampler);
    tinygltf::AnimationChannel channel;
    channel.sampler = 0;
    channel.target_node = 0;
    channel.target_path = "weights";
    animation.channels.push_back(channel);
    model.animations.push_back(std::move(animation));
  }
  write_model(file, model);
}

}  // namespace skinlab::geometry

#include "framework/geometry/import_character.hpp"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace skinlab::geometry {
namespace {

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d out;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out(r, c) = m[r][c];
  }
  return out;
}

Eigen::Matrix4d global_transform(const aiNode* node) {
  Eigen::Matrix4d g = to_eigen(node->mTransformation);
  for (const aiNode* p = node->mParent; p != nullptr; p = p->mParent) {
    g = to_eigen(p->mTransformation) * g;
  }
  return g;
}

/// One mesh as attached to one node (a mesh referenced by two nodes is two instances).
struct Instance {
  const aiNode* node;
  const aiMesh* mesh;
  unsigned mesh_index;
  Eigen::Matrix4d global;  // G(node)
};

void collect_instances(const aiScene& scene, const aiNode* node, std::vector<Instance>& out) {
  const Eigen::Matrix4d g = global_transform(node);
  for (unsigned i = 0; i < node->mNumMeshes; ++i) {
    const unsigned m = node->mMeshes[i];
    if (m < scene.mNumMeshes) out.push_back(Instance{node, scene.mMeshes[m], m, g});
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) {
    collect_instances(scene, node->mChildren[c], out);
  }
}

std::string describe(const Instance& in) {
  std::string s = "mesh " + std::to_string(in.mesh_index);
  if (in.mesh->mName.length > 0) s += " '" + std::string(in.mesh->mName.C_Str()) + "'";
  return s + " (node '" + in.node->mName.C_Str() + "')";
}

std::vector<const aiNode*> path_from_root(const aiNode* node) {
  std::vector<const aiNode*> path;
  for (const aiNode* n = node; n != nullptr; n = n->mParent) path.push_back(n);
  return {path.rbegin(), path.rend()};
}

std::optional<Eigen::Vector3d> metadata_up(const aiScene& scene) {
  if (scene.mMetaData == nullptr) return std::nullopt;
  int32_t axis = -1;
  int32_t sign = 1;
  if (!scene.mMetaData->Get("UpAxis", axis) || axis < 0 || axis > 2) return std::nullopt;
  scene.mMetaData->Get("UpAxisSign", sign);
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  up[axis] = sign < 0 ? -1.0 : 1.0;
  return up;
}


/// A global transform split into a rotation and scales: linear part = U·diag(σ)·Vᵀ (SVD),
/// rotation U·Vᵀ (the nearest orthogonal matrix), translation kept.
struct RigidPart {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  Eigen::Vector3d scales = Eigen::Vector3d::Ones();  ///< the singular values σ
  bool proper = true;  ///< det > 0 (no mirror) and every entry finite
};

RigidPart rigid_part(const Eigen::Matrix4d& m) {
  RigidPart out;
  if (!m.allFinite()) {
    out.proper = false;
    return out;
  }
  const Eigen::Matrix3d linear = m.topLeftCorner<3, 3>();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
  // Copied out before use: reading them through `svd` makes GCC 12 -O3 warn (falsely) that the
  // singular values may be used uninitialised.
  const Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d V = svd.matrixV();
  out.scales = Eigen::Vector3d(svd.singularValues());
  out.proper = linear.determinant() > 0;
  out.transform.linear() = U * V.transpose();
  out.transform.translation() = m.block<3, 1>(0, 3);
  return out;
}

/// Largest |σ_i − scale| / scale.
double scale_error(const Eigen::Vector3d& scales, double scale) {
  return (scales.array() - scale).abs().maxCoeff() / scale;
}

std::string format_scales(const Eigen::Vector3d& s) {
  return std::to_string(s[0]) + ", " + std::to_string(s[1]) + ", " + std::to_string(s[2]);
}

/// Whether the `n` keys have finite times in non-decreasing order and finite values.
template <typename Key>
bool keys_valid(const Key* keys, unsigned n) {
  for (unsigned k = 0; k < n; ++k) {
    const auto& v = keys[k].mValue;
    bool finite = std::isfinite(keys[k].mTime) && std::isfinite(v.x) && std::isfinite(v.y) &&
                  std::isfinite(v.z);
    if constexpr (std::is_same_v<Key, aiQuatKey>) finite = finite && std::isfinite(v.w);
    if (!finite || (k > 0 && keys[k].mTime < keys[k - 1].mTime)) return false;
  }
  return true;
}

/// The index i of the key with t_i ≤ time < t_{i+1} and the fraction of the way to key i + 1;
/// (0, 0) before the first key and (n − 1, 0) after the last (held constant). n ≥ 1.
template <typename Key>
std::pair<unsigned, double> key_segment(const Key* keys, unsigned n, double time) {
  const Key* after = std::upper_bound(keys, keys + n, time,
                                      [](double t, const Key& key) { return t < key.mTime; });
  if (after == keys) return {0, 0.0};
  if (after == keys + n) return {n - 1, 0.0};
  const unsigned i = static_cast<unsigned>(after - keys) - 1;
  const double span = keys[i + 1].mTime - keys[i].mTime;
  return {i, span > 0 ? (time - keys[i].mTime) / span : 0.0};
}

Eigen::Vector3d sample_keys(const aiVectorKey* keys, unsigned n, double time) {
  const auto [i, a] = key_segment(keys, n, time);
  const Eigen::Vector3d v0(keys[i].mValue.x, keys[i].mValue.y, keys[i].mValue.z);
  if (a == 0) return v0;
  const Eigen::Vector3d v1(keys[i + 1].mValue.x, keys[i + 1].mValue.y, keys[i + 1].mValue.z);
  return (1 - a) * v0 + a * v1;
}

Eigen::Quaterniond to_quaternion(const aiQuaternion& q) {
  return Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized();
}

Eigen::Quaterniond sample_keys(const aiQuatKey* keys, unsigned n, double time) {
  const auto [i, a] = key_segment(keys, n, time);
  const Eigen::Quaterniond q0 = to_quaternion(keys[i].mValue);
  if (a == 0) return q0;
  return q0.slerp(a, to_quaternion(keys[i + 1].mValue));  // Eigen takes the shorter arc
}

/// The nodes whose transforms make up the joints' globals (every joint node and its ancestors
/// up to the scene root), parents before children.
struct NodeChain {
  std::vector<const aiNode*> nodes;
  std::vector<int> parent;      ///< index into nodes, −1 for the scene root
  std::vector<int> of_joint;    ///< of_joint[j]: index of joint j's node
  std::unordered_map<const aiNode*, int> index;  ///< the inverse of nodes
};

NodeChain node_chain(const aiNode* root, const std::vector<const aiNode*>& joint_nodes) {
  std::set<const aiNode*> needed;
  for (const aiNode* node : joint_nodes) {
    for (const aiNode* n = node; n != nullptr && needed.insert(n).second; n = n->mParent) {
    }
  }
  NodeChain chain;
  std::function<void(const aiNode*, int)> visit = [&](const aiNode* node, int parent) {
    if (needed.count(node) == 0) return;
    const int i = static_cast<int>(chain.nodes.size());
    chain.index[node] = i;
    chain.nodes.push_back(node);
    chain.parent.push_back(parent);
    for (unsigned c = 0; c < node->mNumChildren; ++c) visit(node->mChildren[c], i);
  };
  visit(root, -1);
  for (const aiNode* node : joint_nodes) chain.of_joint.push_back(chain.index.at(node));
  return chain;
}

/// Samples clip `a` into `clip` (named `clip.name` by the caller); returns "" or why it is left
/// out. `scaled` is set when the reason is a joint's scale.
std::string sample_clip(const aiAnimation& a, const NodeChain& chain,
                        const std::vector<std::string>& joint_names,
                        const std::vector<double>& bind_scale, const ImportOptions& options,
                        ImportedClip& clip, bool& scaled) {
  scaled = false;
  // Channels bind to nodes as assimp binds bones: by name, the first node of that name in the
  // tree. Channels of nodes that place no joint (props, cameras, mesh nodes) do not matter.
  const aiNode* root = chain.nodes.front();
  std::vector<const aiNodeAnim*> channel(chain.nodes.size(), nullptr);
  int animated = 0;
  for (unsigned c = 0; c < a.mNumChannels; ++c) {
    const aiNodeAnim* ch = a.mChannels[c];
    if (ch == nullptr) continue;
    const auto it = chain.index.find(root->FindNode(ch->mNodeName));
    if (it == chain.index.end()) continue;
    if (channel[it->second] != nullptr) continue;  // a repeated channel: the first wins
    if (!keys_valid(ch->mPositionKeys, ch->mNumPositionKeys) ||
        !keys_valid(ch->mRotationKeys, ch->mNumRotationKeys) ||
        !keys_valid(ch->mScalingKeys, ch->mNumScalingKeys)) {
      return std::string("the keys of node '") + ch->mNodeName.C_Str() +
             "' are not finite or not in time order";
    }
    channel[it->second] = ch;
    ++animated;
  }
  if (animated == 0) {
    return "no channel animates a joint or a node above one (" + std::to_string(a.mNumChannels) +
           " node channels, " + std::to_string(a.mNumMorphMeshChannels) + " morph channels)";
  }
  const double ticks_per_second = a.mTicksPerSecond != 0 ? a.mTicksPerSecond : 25.0;
  const double seconds = a.mDuration / ticks_per_second;
  if (!std::isfinite(seconds) || seconds < 0 || ticks_per_second < 0) {
    return "duration " + std::to_string(a.mDuration) + " ticks at " +
           std::to_string(a.mTicksPerSecond) + " ticks per second is not a finite time ≥ 0";
  }
  const double num_frames = std::floor(seconds * options.clip_fps + 1e-9) + 1;
  constexpr double kMaxFrames = 1e6;
  if (num_frames > kMaxFrames) {
    return std::to_string(seconds) + " s at " + std::to_string(options.clip_fps) +
           " fps is more than " + std::to_string(static_cast<long>(kMaxFrames)) + " frames";
  }

  // Rest parts of animated nodes, for channels without keys of some kind.
  struct Rest {
    Eigen::Vector3d position, scaling;
    Eigen::Quaterniond rotation;
  };
  std::vector<Rest> rest(chain.nodes.size());
  for (std::size_t i = 0; i < chain.nodes.size(); ++i) {
    if (channel[i] == nullptr) continue;
    aiVector3D s, p;
    aiQuaternion q;
    chain.nodes[i]->mTransformation.Decompose(s, q, p);
    rest[i] = {Eigen::Vector3d(p.x, p.y, p.z), Eigen::Vector3d(s.x, s.y, s.z), to_quaternion(q)};
  }

  clip.fps = options.clip_fps;
  clip.frames.assign(static_cast<std::size_t>(num_frames), {});
  std::vector<Eigen::Matrix4d> global(chain.nodes.size());
  for (std::size_t f = 0; f < clip.frames.size(); ++f) {
    const double ticks = static_cast<double>(f) / options.clip_fps * ticks_per_second;
    for (std::size_t i = 0; i < chain.nodes.size(); ++i) {
      Eigen::Matrix4d local;
      if (const aiNodeAnim* ch = channel[i]; ch != nullptr) {
        const Eigen::Vector3d p = ch->mNumPositionKeys > 0
                                      ? sample_keys(ch->mPositionKeys, ch->mNumPositionKeys, ticks)
                                      : rest[i].position;
        const Eigen::Quaterniond q = ch->mNumRotationKeys > 0
                                         ? sample_keys(ch->mRotationKeys, ch->mNumRotationKeys, ticks)
                                         : rest[i].rotation;
        const Eigen::Vector3d s = ch->mNumScalingKeys > 0
                                      ? sample_keys(ch->mScalingKeys, ch->mNumScalingKeys, ticks)
                                      : rest[i].scaling;
        local.setIdentity();
        local.topLeftCorner<3, 3>() = q.toRotationMatrix() * s.asDiagonal();
        local.block<3, 1>(0, 3) = p;
      } else {
        local = to_eigen(chain.nodes[i]->mTransformation);
      }
      global[i] = chain.parent[i] < 0 ? local : global[chain.parent[i]] * local;
    }
    auto& frame = clip.frames[f];
    frame.resize(chain.of_joint.size());
    for (std::size_t j = 0; j < chain.of_joint.size(); ++j) {
      const RigidPart part = rigid_part(global[chain.of_joint[j]]);
      if (!part.transform.matrix().allFinite()) {
        return "joint '" + joint_names[j] + "' has a non-finite transform at frame " +
               std::to_string(f);
      }
      if (!part.proper || scale_error(part.scales, bind_scale[j]) > options.clip_scale_tolerance) {
        scaled = true;
        return "joint '" + joint_names[j] + "' is scaled at frame " + std::to_string(f) +
               " (scales " + format_scales(part.scales) + (part.proper ? "" : ", mirrored") +
               "; bind " + std::to_string(bind_scale[j]) + ")";
      }
      frame[j] = part.transform;
    }
  }
  return "";
}
}  // namespace

Character import_character(const std::filesystem::path& file, const ImportOptions& options,
                           ImportReport* report, ImportedMotion* motion) {
  const std::string src = file.string();
  const std::string at = src + ": ";
  if (!std::isfinite(options.clip_fps) || options.clip_fps < 0) {
    throw GeometryError(at + "clip_fps must be finite and ≥ 0, not " +
                        std::to_string(options.clip_fps));
  }
  if (options.max_clips < 0) {
    throw GeometryError(at + "max_clips must be ≥ 0, not " + std::to_string(options.max_clips));
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    throw IoError(at + (std::filesystem::exists(file, ec) ? "not a regular file"
                                                          : "no such file"));
  }

  Assimp::Importer importer;
  importer.SetPropertyBool(AI_CONFIG_IMPORT_REMOVE_EMPTY_BONES, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
  unsigned flags = aiProcess_Triangulate;
  if (options.join_identical_vertices) flags |= aiProcess_JoinIdenticalVertices;
  const aiScene* scene = importer.ReadFile(src, flags);
  if (scene == nullptr) {
    throw IoError(at + "assimp cannot read it: " + importer.GetErrorString());
  }
  if (scene->mRootNode == nullptr || scene->mNumMeshes == 0) {
    throw GeometryError(at + "the file contains no mesh");
  }

  std::vector<Instance> instances;
  collect_instances(*scene, scene->mRootNode, instances);
  if (instances.empty()) {
    throw GeometryError(at + "the file has " + std::to_string(scene->mNumMeshes) +
                        " meshes, but no node instantiates any of them");
  }

  // Bone nodes, and the bind-pose global transform of each (first mesh that binds it wins; the
  // others are compared with it).
  std::map<const aiNode*, Eigen::Matrix4d> bind;
  std::vector<const aiNode*> bone_nodes;  // in first-seen order
  ImportReport rep;
  double mismatch = 0;
  // How differently two meshes bind one bone (ImportedMotion::no_bind): translation in file
  // units, linear part relative to its norm.
  double spread_translation = 0, spread_linear = 0;
  std::string spread_joint;
  for (const Instance& in : instances) {
    for (unsigned b = 0; b < in.mesh->mNumBones; ++b) {
      const aiBone* bone = in.mesh->mBones[b];
      const aiNode* node = scene->mRootNode->FindNode(bone->mName);
      if (node == nullptr) {
        throw GeometryError(at + describe(in) + ": bone '" + bone->mName.C_Str() +
                            "' has no node of that name");
      }
      const Eigen::Matrix4d B = in.global * to_eigen(bone->mOffsetMatrix).inverse();
      const Eigen::Vector3d node_position = global_transform(node).block<3, 1>(0, 3);
      auto [it, fresh] = bind.emplace(node, B);
      if (fresh) bone_nodes.push_back(node);
      if (!fresh) {
        const Eigen::Matrix3d first = it->second.topLeftCorner<3, 3>();
        const double t = (B.block<3, 1>(0, 3) - it->second.block<3, 1>(0, 3)).norm();
        const double l = (B.topLeftCorner<3, 3>() - first).norm() / first.norm();
        if (t > spread_translation || l > spread_linear) spread_joint = node->mName.C_Str();
        spread_translation = std::max(spread_translation, t);
        spread_linear = std::max(spread_linear, l);
      }
      const double d = std::max((B.block<3, 1>(0, 3) - node_position).norm(),
                                (B.block<3, 1>(0, 3) - it->second.block<3, 1>(0, 3)).norm());
      if (d > mismatch || rep.max_bind_pose_mismatch_joint.empty()) {
        mismatch = d;
        rep.max_bind_pose_mismatch_joint = node->mName.C_Str();
      }
    }
  }
  if (bone_nodes.empty()) {
    throw GeometryError(at + "no bones: none of its " + std::to_string(instances.size()) +
                        " mesh instances is skinned, so it carries no skeleton");
  }
  rep.num_bones = static_cast<int>(bone_nodes.size());
  rep.max_bind_pose_mismatch = mismatch;

  // The lowest common ancestor of all bone nodes is the longest common prefix of their paths.
  std::vector<const aiNode*> lca_path = path_from_root(bone_nodes[0]);
  for (const aiNode* node : bone_nodes) {
    const auto path = path_from_root(node);
    std::size_t k = 0;
    while (k < lca_path.size() && k < path.size() && lca_path[k] == path[k]) ++k;
    lca_path.resize(k);
  }
  const aiNode* lca = lca_path.back();  // non-empty: every path starts at the root node
  std::set<const aiNode*> keep;
  for (const aiNode* node : bone_nodes) {
    for (const aiNode* n = node; n != nullptr; n = n->mParent) {
      if (!keep.insert(n).second || n == lca) break;
    }
  }

  // Joints in depth-first pre-order below the LCA.
  Skeleton skeleton;
  std::unordered_map<const aiNode*, int> joint_of;
  std::set<std::string> used_names;
  std::vector<const aiNode*> joint_nodes;
  // B(bone), or G(node) for a joint that is no bone: its translation is the joint's position.
  std::vector<Eigen::Matrix4d> joint_bind;
  std::function<void(const aiNode*, int)> visit = [&](const aiNode* node, int parent) {
    if (keep.count(node) == 0) return;
    std::string name = node->mName.C_Str();
    if (name.empty()) name = "joint" + std::to_string(skeleton.names.size());
    for (int n = 2; used_names.count(name) > 0; ++n) {
      name = std::string(node->mName.C_Str()) + "_" + std::to_string(n);
    }
    used_names.insert(name);
    const int j = static_cast<int>(skeleton.names.size());
    joint_of[node] = j;
    skeleton.names.push_back(name);
    skeleton.parents.push_back(parent);
    const auto b = bind.find(node);
    joint_nodes.push_back(node);
    joint_bind.push_back(b != bind.end() ? b->second : global_transform(node));
    for (unsigned c = 0; c < node->mNumChildren; ++c) visit(node->mChildren[c], j);
  };
  visit(lca, -1);
  skeleton.positions.resize(static_cast<Eigen::Index>(joint_bind.size()), 3);
  for (std::size_t j = 0; j < joint_bind.size(); ++j) {
    skeleton.positions.row(static_cast<Eigen::Index>(j)) = joint_bind[j].block<3, 1>(0, 3).transpose();
  }

  // Mesh and weights, instance by instance.
  Eigen::Index num_vertices = 0;
  Eigen::Index num_faces = 0;
  for (const Instance& in : instances) {
    num_vertices += in.mesh->mNumVertices;
    for (unsigned f = 0; f < in.mesh->mNumFaces; ++f) num_faces += in.mesh->mFaces[f].mNumIndices == 3;
  }
  Character character;
  character.name = file.stem().string();
  character.mesh.V.resize(num_vertices, 3);
  character.mesh.F.resize(num_faces, 3);
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::Index vertex_offset = 0;
  Eigen::Index face = 0;
  for (const Instance& in : instances) {
    const aiMesh& mesh = *in.mesh;
    const Eigen::Affine3d g(in.global);
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& p = mesh.mVertices[v];
      character.mesh.V.row(vertex_offset + v) = (g * Eigen::Vector3d(p.x, p.y, p.z)).transpose();
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& aface = mesh.mFaces[f];
      if (aface.mNumIndices != 3) continue;
      for (int k = 0; k < 3; ++k) {
        if (aface.mIndices[k] >= mesh.mNumVertices) {
          throw GeometryError(at + describe(in) + ": face " + std::to_string(f) +
                              " refers to vertex " + std::to_string(aface.mIndices[k]) +
                              ", but the mesh has " + std::to_string(mesh.mNumVertices));
        }
        character.mesh.F(face, k) = static_cast<int>(vertex_offset + aface.mIndices[k]);
      }
      ++face;
    }

    std::vector<double> weight_sum(mesh.mNumVertices, 0.0);
    for (unsigned b = 0; b < mesh.mNumBones; ++b) {
      const aiBone& bone = *mesh.mBones[b];
      const int j = joint_of.at(scene->mRootNode->FindNode(bone.mName));
      for (unsigned w = 0; w < bone.mNumWeights; ++w) {
        const aiVertexWeight& vw = bone.mWeights[w];
        const std::string where =
            at + describe(in) + ", bone '" + bone.mName.C_Str() + "', weight " + std::to_string(w);
        if (vw.mVertexId >= mesh.mNumVertices) {
          throw GeometryError(where + ": vertex index " + std::to_string(vw.mVertexId) +
                              " out of range (the mesh has " + std::to_string(mesh.mNumVertices) +
                              " vertices)");
        }
        if (!std::isfinite(vw.mWeight) || vw.mWeight < 0) {
          throw GeometryError(where + ": weight " + std::to_string(vw.mWeight) + " of vertex " +
                              std::to_string(vw.mVertexId) + " is negative or not finite");
        }
        if (vw.mWeight == 0) continue;
        weight_sum[vw.mVertexId] += vw.mWeight;
        triplets.emplace_back(static_cast<int>(vertex_offset + vw.mVertexId), j, vw.mWeight);
      }
    }

    // Rigid attachment: unweighted vertices follow the nearest joint at or above the mesh node.
    int host = -1;
    for (const aiNode* n = in.node; n != nullptr && host < 0; n = n->mParent) {
      if (const auto it = joint_of.find(n); it != joint_of.end()) host = it->second;
    }
    // Where the host's bind pose would carry them: B(host) · G(host node)⁻¹ (the identity when
    // the node hierarchy is stored in the bind pose); measured, not applied.
    Eigen::Matrix4d to_bind = Eigen::Matrix4d::Identity();
    if (host >= 0) to_bind = joint_bind[host] * global_transform(joint_nodes[host]).inverse();
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      if (weight_sum[v] > 0) continue;
      if (host < 0) {
        throw GeometryError(at + describe(in) + ": vertex " + std::to_string(v) +
                            " has no bone weight and the mesh node is not below any joint of "
                            "the skeleton (rooted at '" + skeleton.names[0] + "')");
      }
      triplets.emplace_back(static_cast<int>(vertex_offset + v), host, 1.0);
      ++rep.num_rigid_vertices;
      const Eigen::Vector3d x = character.mesh.V.row(vertex_offset + v).transpose();
      const double d = ((to_bind * x.homogeneous()).head<3>() - x).norm();
      if (d > rep.max_rigid_misplacement) {
        rep.max_rigid_misplacement = d;
        rep.max_rigid_misplacement_joint = skeleton.names[host];
      }
    }
    vertex_offset += mesh.mNumVertices;
  }

  character.skeleton = std::move(skeleton);
  character.weights.resize(num_vertices, character.skeleton.num_joints());
  character.weights.setFromTriplets(triplets.begin(), triplets.end());
  character.validate(options.weights);

  double diagonal = 0;
  if (character.mesh.V.rows() > 0) {
    diagonal = (character.mesh.V.colwise().maxCoeff() - character.mesh.V.colwise().minCoeff()).norm();
  }
  if (mismatch > options.bind_pose_tolerance * diagonal) {
    spdlog::warn("{}: bind pose from the bone offsets and node transforms differ by up to {} ({} "
                 "of the bounding-box diagonal) at joint '{}'; joints use the offsets",
                 src, mismatch, mismatch / diagonal, rep.max_bind_pose_mismatch_joint);
  }
  if (rep.max_rigid_misplacement > options.bind_pose_tolerance * diagonal) {
    spdlog::warn("{}: unweighted vertices attached to joint '{}' lie up to {} ({} of the "
                 "bounding-box diagonal) from where its bind pose puts them (its node is stored "
                 "in another pose); they are kept where the node hierarchy puts them",
                 src, rep.max_rigid_misplacement_joint, rep.max_rigid_misplacement,
                 rep.max_rigid_misplacement / diagonal);
  }
  rep.num_mesh_instances = static_cast<int>(instances.size());
  rep.source_up = metadata_up(*scene);
  if (report != nullptr) *report = rep;
  if (motion != nullptr) {
    *motion = ImportedMotion{};
    motion->num_file_clips = static_cast<int>(scene->mNumAnimations);
    const auto& names = character.skeleton.names;
    // Bind transforms: rigid once their uniform scale is divided out (see the header).
    std::vector<double> bind_scale;
    for (std::size_t j = 0; j < joint_bind.size() && motion->no_bind.empty(); ++j) {
      const RigidPart part = rigid_part(joint_bind[j]);
      const double scale = part.scales.mean();
      if (!part.proper || !(scale > 0) ||
          scale_error(part.scales, scale) > options.clip_scale_tolerance) {
        motion->no_bind = "the bind transform of joint '" + names[j] +
                          "' is not a rotation with a uniform positive scale (scales " +
                          format_scales(part.scales) + (part.proper ? "" : ", mirrored") + ")";
      }
      motion->bind.push_back(part.transform);
      bind_scale.push_back(scale);
    }
    if (motion->no_bind.empty() && (spread_translation > options.bind_pose_tolerance * diagonal ||
                                    spread_linear > options.clip_scale_tolerance)) {
      motion->no_bind = "meshes bind joint '" + spread_joint + "' differently (by up to " +
                        std::to_string(spread_translation) + " file units in translation, " +
                        std::to_string(spread_linear) + " relative in rotation and scale), so "
                        "one bind transform per joint cannot pose them all";
    }
    if (!motion->no_bind.empty()) {
      motion->bind.clear();
    } else if (options.clip_fps > 0) {
      const NodeChain chain = node_chain(scene->mRootNode, joint_nodes);
      for (unsigned k = 0; k < scene->mNumAnimations; ++k) {
        if (static_cast<int>(motion->clips.size()) >= options.max_clips) {
          motion->num_unread_clips = static_cast<int>(scene->mNumAnimations - k);
          break;
        }
        const aiAnimation* a = scene->mAnimations[k];
        if (a == nullptr) continue;
        ImportedClip clip;
        clip.name = a->mName.length > 0 ? std::string(a->mName.C_Str()) : "clip" + std::to_string(k);
        bool scaled = false;
        const std::string why = sample_clip(*a, chain, names, bind_scale, options, clip, scaled);
        if (why.empty()) {
          motion->clips.push_back(std::move(clip));
        } else {
          motion->num_scaled_clips += scaled;
          motion->left_out.push_back("'" + clip.name + "': " + why);
        }
      }
    }
  }
  return character;
}

}  // namespace skinlab::geometry

#include "framework/geometry/import_character.hpp"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <unordered_map>
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

}  // namespace

Character import_character(const std::filesystem::path& file, const ImportOptions& options,
                           ImportReport* report) {
  const std::string src = file.string();
  const std::string at = src + ": ";
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
  std::vector<Eigen::Vector3d> positions;
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
    const Eigen::Matrix4d g = b != bind.end() ? b->second : global_transform(node);
    positions.push_back(g.block<3, 1>(0, 3));
    for (unsigned c = 0; c < node->mNumChildren; ++c) visit(node->mChildren[c], j);
  };
  visit(lca, -1);
  skeleton.positions.resize(static_cast<Eigen::Index>(positions.size()), 3);
  for (std::size_t j = 0; j < positions.size(); ++j) {
    skeleton.positions.row(static_cast<Eigen::Index>(j)) = positions[j].transpose();
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
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      if (weight_sum[v] > 0) continue;
      if (host < 0) {
        throw GeometryError(at + describe(in) + ": vertex " + std::to_string(v) +
                            " has no bone weight and the mesh node is not below any joint of "
                            "the skeleton (rooted at '" + skeleton.names[0] + "')");
      }
      triplets.emplace_back(static_cast<int>(vertex_offset + v), host, 1.0);
      ++rep.num_rigid_vertices;
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
  rep.num_mesh_instances = static_cast<int>(instances.size());
  rep.source_up = metadata_up(*scene);
  if (report != nullptr) *report = rep;
  return character;
}

}  // namespace skinlab::geometry

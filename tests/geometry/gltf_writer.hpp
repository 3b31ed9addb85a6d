#pragma once
// A minimal glTF 2.0 writer for import tests: meshes with optional skin attributes, skins with
// inverse bind matrices, node animations, and nodes given as JSON objects by the test, all in
// one .gltf file with an embedded base64 buffer
// (spec: https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html).

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace skinlab::testing {

struct GltfMesh {
  std::string name;
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::uint16_t> indices;               // 3 per triangle
  std::vector<std::array<std::uint8_t, 4>> joints;  // empty: not skinned
  std::vector<std::array<float, 4>> weights;
};

struct GltfSkin {
  std::vector<int> joints;              // node indices
  std::vector<Eigen::Matrix4f> inverse_bind;  // one per joint, as ordinary (row, col) matrices
};

// One animated property of one node: key times (seconds) and values (3 floats per key for
// "translation" and "scale", 4 for "rotation", a quaternion x, y, z, w), one sampler each.
struct GltfChannel {
  int node = 0;
  std::string path;  // "translation", "rotation" or "scale"
  std::vector<float> times;
  std::vector<float> values;
};

struct GltfAnimation {
  std::string name;
  std::vector<GltfChannel> channels;
};

struct GltfScene {
  std::vector<std::string> nodes;  // JSON objects, e.g. {"name":"a","children":[1]}
  std::vector<int> roots;          // scene root nodes
  std::vector<GltfMesh> meshes;
  std::vector<GltfSkin> skins;
  std::vector<GltfAnimation> animations;

  std::string json() const {
    std::string buffer, views, accessors;
    int count = 0;
    auto add = [&](const void* data, std::size_t bytes, const std::string& accessor) {
      while (buffer.size() % 4 != 0) buffer.push_back('\0');
      if (!views.empty()) views += ",";
      views += "{\"buffer\":0,\"byteOffset\":" + std::to_string(buffer.size()) +
               ",\"byteLength\":" + std::to_string(bytes) + "}";
      buffer.append(static_cast<const char*>(data), bytes);
      if (!accessors.empty()) accessors += ",";
      accessors += "{\"bufferView\":" + std::to_string(count) + "," + accessor + "}";
      return count++;
    };
    std::string mesh_json, skin_json, node_json;
    for (const auto& m : meshes) {
      Eigen::Vector3f lo = m.positions[0], hi = m.positions[0];
      for (const auto& p : m.positions) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
      const std::string n = std::to_string(m.positions.size());
      const int pos = add(m.positions.data(), 12 * m.positions.size(),
                          "\"componentType\":5126,\"count\":" + n + ",\"type\":\"VEC3\",\"min\":[" +
                              std::to_string(lo.x()) + "," + std::to_string(lo.y()) + "," +
                              std::to_string(lo.z()) + "],\"max\":[" + std::to_string(hi.x()) +
                              "," + std::to_string(hi.y()) + "," + std::to_string(hi.z()) + "]");
      const int idx = add(m.indices.data(), 2 * m.indices.size(),
                          "\"componentType\":5123,\"count\":" + std::to_string(m.indices.size()) +
                              ",\"type\":\"SCALAR\"");
      std::string attributes = "\"POSITION\":" + std::to_string(pos);
      if (!m.joints.empty()) {
        const int j = add(m.joints.data(), 4 * m.joints.size(),
                          "\"componentType\":5121,\"count\":" + n + ",\"type\":\"VEC4\"");
        const int w = add(m.weights.data(), 16 * m.weights.size(),
                          "\"componentType\":5126,\"count\":" + n + ",\"type\":\"VEC4\"");
        attributes += ",\"JOINTS_0\":" + std::to_string(j) + ",\"WEIGHTS_0\":" + std::to_string(w);
      }
      if (!mesh_json.empty()) mesh_json += ",";
      mesh_json += "{\"name\":\"" + m.name + "\",\"primitives\":[{\"attributes\":{" + attributes +
                   "},\"indices\":" + std::to_string(idx) + "}]}";
    }
    for (const auto& s : skins) {
      std::vector<float> columns;  // glTF matrices are column-major
      for (const auto& m : s.inverse_bind) {
        for (int c = 0; c < 4; ++c) {
          for (int r = 0; r < 4; ++r) columns.push_back(m(r, c));
        }
      }
      const int ibm = add(columns.data(), 4 * columns.size(),
                          "\"componentType\":5126,\"count\":" +
                              std::to_string(s.inverse_bind.size()) + ",\"type\":\"MAT4\"");
      std::string joints;
      for (int j : s.joints) joints += (joints.empty() ? "" : ",") + std::to_string(j);
      if (!skin_json.empty()) skin_json += ",";
      skin_json += "{\"joints\":[" + joints + "],\"inverseBindMatrices\":" + std::to_string(ibm) + "}";
    }
    std::string animation_json;
    for (const auto& a : animations) {
      std::string samplers, channels;
      for (std::size_t c = 0; c < a.channels.size(); ++c) {
        const GltfChannel& ch = a.channels[c];
        float lo = ch.times.front(), hi = ch.times.front();
        for (float t : ch.times) {
          lo = std::min(lo, t);
          hi = std::max(hi, t);
        }
        const std::string keys = std::to_string(ch.times.size());
        const int input = add(ch.times.data(), 4 * ch.times.size(),
                              "\"componentType\":5126,\"count\":" + keys +
                                  ",\"type\":\"SCALAR\",\"min\":[" + std::to_string(lo) +
                                  "],\"max\":[" + std::to_string(hi) + "]");
        const int output = add(ch.values.data(), 4 * ch.values.size(),
                               "\"componentType\":5126,\"count\":" + keys + ",\"type\":\"" +
                                   (ch.path == "rotation" ? "VEC4" : "VEC3") + "\"");
        samplers += (c == 0 ? "" : ",") + std::string("{\"input\":") + std::to_string(input) +
                    ",\"output\":" + std::to_string(output) + ",\"interpolation\":\"LINEAR\"}";
        channels += (c == 0 ? "" : ",") + std::string("{\"sampler\":") + std::to_string(c) +
                    ",\"target\":{\"node\":" + std::to_string(ch.node) + ",\"path\":\"" +
                    ch.path + "\"}}";
      }
      if (!animation_json.empty()) animation_json += ",";
      animation_json += "{\"name\":\"" + a.name + "\",\"samplers\":[" + samplers +
                        "],\"channels\":[" + channels + "]}";
    }
    for (const auto& n : nodes) node_json += (node_json.empty() ? "" : ",") + n;
    std::string root_json;
    for (int r : roots) root_json += (root_json.empty() ? "" : ",") + std::to_string(r);
    std::string out = "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[" +
                      root_json + "]}],\"nodes\":[" + node_json + "],\"meshes\":[" + mesh_json +
                      "]";
    if (!skin_json.empty()) out += ",\"skins\":[" + skin_json + "]";
    if (!animation_json.empty()) out += ",\"animations\":[" + animation_json + "]";
    out += ",\"buffers\":[{\"byteLength\":" + std::to_string(buffer.size()) +
           ",\"uri\":\"data:application/octet-stream;base64," + base64(buffer) +
           "\"}],\"bufferViews\":[" + views + "],\"accessors\":[" + accessors + "]}";
    return out;
  }

  static std::string base64(const std::string& bytes) {
    static const char* table =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    std::size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
      const unsigned n = (static_cast<unsigned char>(bytes[i]) << 16) |
                         (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                         static_cast<unsigned char>(bytes[i + 2]);
      for (int k = 3; k >= 0; --k) out.push_back(table[(n >> (6 * k)) & 63]);
    }
    const std::size_t rest = bytes.size() - i;
    if (rest > 0) {
      unsigned n = static_cast<unsigned char>(bytes[i]) << 16;
      if (rest == 2) n |= static_cast<unsigned char>(bytes[i + 1]) << 8;
      out.push_back(table[(n >> 18) & 63]);
      out.push_back(table[(n >> 12) & 63]);
      out.push_back(rest == 2 ? table[(n >> 6) & 63] : '=');
      out.push_back('=');
    }
    return out;
  }
};

}  // namespace skinlab::testing

// glTF morph-target animation (what `skinlab generate` writes for viewing a mesh sequence):
// loaded back with TinyGLTF, the base mesh plus each keyframe's weighted targets gives every
// frame back.

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <cmath>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/core/error.hpp"
#include "framework/geometry/gltf_export.hpp"
#include "tests/geometry/test_meshes.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::TempDir;

/// Accessor `index` of `model` as floats (tightly packed, as our writer lays them out).
std::vector<float> floats(const tinygltf::Model& model, int index) {
  const tinygltf::Accessor& a = model.accessors.at(static_cast<std::size_t>(index));
  const tinygltf::BufferView& view = model.bufferViews.at(static_cast<std::size_t>(a.bufferView));
  const auto* p = reinterpret_cast<const float*>(model.buffers.at(0).data.data() + view.byteOffset +
                                                 a.byteOffset);
  const int width = a.type == TINYGLTF_TYPE_VEC3 ? 3 : 1;
  return {p, p + a.count * static_cast<std::size_t>(width)};
}

/// A grid bending over 4 frames.
std::vector<Eigen::MatrixXd> bending_frames(const geometry::Mesh& mesh) {
  std::vector<Eigen::MatrixXd> frames;
  for (int t = 0; t < 4; ++t) {
    Eigen::MatrixXd V = mesh.V;
    for (int v = 0; v < V.rows(); ++v) V(v, 2) = 0.1 * t * V(v, 0) * V(v, 0) + 0.01 * t;
    frames.push_back(V);
  }
  return frames;
}

TEST(GltfMorphAnimation, KeyframesReproduceEveryFrame) {
  const geometry::Mesh mesh = testing::grid(3, 2, 0.5);
  const std::vector<Eigen::MatrixXd> frames = bending_frames(mesh);
  TempDir dir;
  for (const std::string name : {"bend.glb", "bend.gltf"}) {
    geometry::write_gltf_morph_animation(dir / name, "bend", mesh.F, frames, 30.0);
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    const std::string bytes = read_file(dir / name);
    const bool ok =
        name == "bend.glb"
            ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                          reinterpret_cast<const unsigned char*>(bytes.data()),
                                          static_cast<unsigned>(bytes.size()))
            : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(),
                                         static_cast<unsigned>(bytes.size()), "");
    ASSERT_TRUE(ok) << err;
    const tinygltf::Primitive& p = model.meshes.at(0).primitives.at(0);
    ASSERT_EQ(p.targets.size(), 3u);
    EXPECT_EQ(model.meshes[0].weights, std::vector<double>(3, 0.0));
    const std::vector<float> base = floats(model, p.attributes.at("POSITION"));
    EXPECT_EQ(model.accessors.at(static_cast<std::size_t>(p.indices)).count,
              static_cast<std::size_t>(mesh.F.rows()) * 3);
    const tinygltf::Animation& animation = model.animations.at(0);
    ASSERT_EQ(animation.channels.at(0).target_path, "weights");
    EXPECT_EQ(animation.channels[0].target_node, 0);
    const std::vector<float> times = floats(model, animation.samplers.at(0).input);
    const std::vector<float> weights = floats(model, animation.samplers.at(0).output);
    ASSERT_EQ(times.size(), 4u);
    ASSERT_EQ(weights.size(), 12u);
    for (int k = 0; k < 4; ++k) {
      EXPECT_FLOAT_EQ(times[k], k / 30.0f);
      for (int v = 0; v < mesh.num_vertices(); ++v) {
        for (int a = 0; a < 3; ++a) {
          double x = base[v * 3 + a];
          for (int t = 0; t < 3; ++t) {
            x += weights[k * 3 + t] * floats(model, p.targets[t].at("POSITION"))[v * 3 + a];
          }
          EXPECT_NEAR(x, frames[k](v, a), 1e-6) << "keyframe " << k << ", vertex " << v;
        }
      }
    }
  }
}

TEST(GltfMorphAnimation, BadInputIsNamedAndWritesNothing) {
  const geometry::Mesh mesh = testing::grid(2, 2, 0.5);
  std::vector<Eigen::MatrixXd> frames = bending_frames(mesh);
  TempDir dir;
  frames[2].conservativeResize(frames[2].rows() - 1, 3);
  testing::expect_error<Error>(
      [&] { geometry::write_gltf_morph_animation(dir / "a.glb", "a", mesh.F, frames, 30); },
      {"a.glb", "frame 2", "like frame 0"});
  testing::expect_error<Error>(
      [&] { geometry::write_gltf_morph_animation(dir / "a.obj", "a", mesh.F, frames, 30); },
      {"a.obj", "extension"});
  testing::expect_error<Error>(
      [&] { geometry::write_gltf_morph_animation(dir / "a.glb", "a", mesh.F, {mesh.V}, 0); },
      {"a.glb", "frames per second"});
  EXPECT_FALSE(std::filesystem::exists(dir / "a.glb"));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

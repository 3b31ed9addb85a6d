#pragma once
// Shared by the data tests: the real Minetest player (minetest-data, CC BY-SA 3.0) through the
// `folder` builder, a small hand-made PreparedCharacter, and a field-by-field comparison of two.

#include <gtest/gtest.h>

#include <string>

#include "framework/data/source.hpp"
#include "framework/core/config.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/dataset_file.hpp"

namespace skinlab::testing {

inline const char* kMinetestModels =
    "/usr/share/games/minetest/games/minetest_game/mods/player_api/models";

/// The `folder` builder built through the registry, as `skinlab prepare` builds it.
inline std::shared_ptr<datasets::DatasetBuilder> folder_builder(const std::string& path,
                                                                const std::string& extra = "") {
  const auto config = config::Config::parse("type: folder\npath: " + path + "\n" + extra);
  return dataset_registry().create(config.root());
}

inline datasets::SourceCharacter minetest_player() {
  std::vector<datasets::Excluded> excluded;
  auto characters = folder_builder(kMinetestModels, "licence: CC-BY-SA-3.0\n")->read(excluded);
  if (characters.size() != 1) throw std::runtime_error("expected the one Minetest player");
  return characters[0];
}

/// Two triangles, three joints (root → a, root → b), one animation of two frames: every field of
/// the format set to something checkable.
inline data::PreparedCharacter tiny_character(const std::string& name) {
  data::PreparedCharacter c;
  c.name = name;
  c.V = data::RowMatrixXd(4, 3);
  c.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0.5;
  c.F = data::RowMatrixXi(2, 3);
  c.F << 0, 1, 2, 1, 3, 2;
  c.joint_names = {"root", "a", "b"};
  c.parents = {-1, 0, 0};
  c.joints = data::RowMatrixXd(3, 3);
  c.joints << 0.5, 0.5, 0, 0.2, 0.8, 0, 0.8, 0.8, 0;
  c.bones = data::RowMatrixXi(4, 2);
  c.bones << 0, 1, 1, 1, 0, 2, 2, 2;
  c.weights.resize(4, 3);
  c.weights.insert(0, 0) = 1;
  c.weights.insert(1, 0) = 0.25;
  c.weights.insert(1, 1) = 0.75;
  c.weights.insert(2, 2) = 1;
  c.weights.insert(3, 1) = 0.5;
  c.weights.insert(3, 2) = 0.5;
  c.weights.makeCompressed();
  c.vertex_map = {0, 1, 2, 3, 1};
  c.normalisation(0, 0) = 2;
  c.normalisation(1, 3) = -0.5;
  c.subdivision_levels = 1;
  data::DistanceData d;
  d.D = data::RowMatrixXf::Random(4, 4).cwiseAbs();
  d.topk_index = data::RowMatrixXi(4, 2);
  d.topk_index << 0, 1, 1, 2, 2, 3, 3, 0;
  d.topk_distance = data::RowMatrixXf::Constant(4, 2, 0.5f);
  d.targets = data::RowMatrixXf::Constant(4, 2, 0.25f);
  c.distances["euclidean"] = d;
  c.one_ring_edges = data::RowMatrixXi(2, 2);
  c.one_ring_edges << 0, 1, 1, 0;
  c.geodesic_edges = data::RowMatrixXi(1, 2);
  c.geodesic_edges << 2, 3;
  c.laplacian_indices = data::RowMatrixXi(2, 2);
  c.laplacian_indices << 0, 0, 0, 1;
  c.laplacian_values = {1.0, -1.0};
  c.source = "test";
  c.path = "dir/" + name + ".fbx";
  c.licence = "CC0-1.0";
  c.attribution = "skinlab tests";
  c.skeleton = "tri";
  data::AnimationData a;
  a.name = "wave";
  a.fps = 24;
  a.num_frames = 2;
  for (int i = 0; i < 2 * 3 * 12; ++i) a.frames.push_back(0.01f * i);
  for (int i = 0; i < 3 * 12; ++i) a.bind.push_back(-0.02f * i);
  c.animations.push_back(a);
  c.bind = a.bind;
  return c;
}

/// Every field of two prepared characters equal (the weights to float32 precision, as stored).
inline void expect_equal(const data::PreparedCharacter& a, const data::PreparedCharacter& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.V, b.V);
  EXPECT_EQ(a.F, b.F);
  EXPECT_EQ(a.joint_names, b.joint_names);
  EXPECT_EQ(a.leaf_tips, b.leaf_tips);
  EXPECT_EQ(a.parents, b.parents);
  EXPECT_EQ(a.joints, b.joints);
  EXPECT_EQ(a.bones, b.bones);
  EXPECT_TRUE(Eigen::MatrixXd(a.weights).isApprox(Eigen::MatrixXd(b.weights), 1e-7));
  EXPECT_EQ(a.weights.nonZeros(), b.weights.nonZeros());
  EXPECT_EQ(a.vertex_map, b.vertex_map);
  EXPECT_EQ(a.normalisation, b.normalisation);
  EXPECT_EQ(a.subdivision_levels, b.subdivision_levels);
  ASSERT_EQ(a.distances.size(), b.distances.size());
  for (const auto& [type, d] : a.distances) {
    const auto& e = b.distances.at(type);
    EXPECT_EQ(d.D, e.D) << type;
    EXPECT_EQ(d.topk_index, e.topk_index);
    EXPECT_EQ(d.topk_distance, e.topk_distance);
    EXPECT_EQ(d.targets, e.targets);
  }
  EXPECT_EQ(a.priors, b.priors);
  EXPECT_EQ(a.one_ring_edges, b.one_ring_edges);
  EXPECT_EQ(a.geodesic_edges, b.geodesic_edges);
  EXPECT_EQ(a.laplacian_indices, b.laplacian_indices);
  EXPECT_EQ(a.laplacian_values, b.laplacian_values);
  EXPECT_EQ(a.source, b.source);
  EXPECT_EQ(a.path, b.path);
  EXPECT_EQ(a.licence, b.licence);
  EXPECT_EQ(a.attribution, b.attribution);
  EXPECT_EQ(a.skeleton, b.skeleton);
  EXPECT_EQ(a.augmented_from, b.augmented_from);
  EXPECT_EQ(a.bind, b.bind);
  ASSERT_EQ(a.animations.size(), b.animations.size());
  for (std::size_t i = 0; i < a.animations.size(); ++i) {
    EXPECT_EQ(a.animations[i].name, b.animations[i].name);
    EXPECT_EQ(a.animations[i].fps, b.animations[i].fps);
    EXPECT_EQ(a.animations[i].num_frames, b.animations[i].num_frames);
    EXPECT_EQ(a.animations[i].frames, b.animations[i].frames);
    EXPECT_EQ(a.animations[i].bind, b.animations[i].bind);
  }
}

}  // namespace skinlab::testing

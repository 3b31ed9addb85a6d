#pragma once
// Shared by the data tests: the real Minetest player (minetest-data, CC BY-SA 3.0) through the
// `folder` builder, and a small hand-made PreparedCharacter.

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
  return c;
}

}  // namespace skinlab::testing

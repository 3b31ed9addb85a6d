// data::to_tensors and data::scatter_to_bones: shapes, dtypes, the renormalised targets, the full
// bone weights by the preprocessing's rule, the Laplacian as sparse COO, and the scatter with its
// gradient and argument checks.

#include <gtest/gtest.h>

#include "framework/data/preprocess.hpp"
#include "framework/tensors/candidates.hpp"
#include "framework/tensors/tensors.hpp"
#include "tests/data/data_fixtures.hpp"
#include "tests/test_util.hpp"
#include "tests/train/train_fixtures.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::expect_error;

TEST(ToTensors, ShapesTypesAndValuesOfAPreparedCharacter) {
  const data::PreparedCharacter p = testing::prepared_tube(1);
  const data::CharacterTensors c = data::to_tensors(p, "euclidean");
  const std::int64_t nv = p.num_vertices(), nb = p.num_bones();
  EXPECT_EQ(c.name, "tube_1");
  EXPECT_EQ(c.distance, "euclidean");
  EXPECT_EQ(c.num_vertices(), nv);
  EXPECT_EQ(c.num_bones(), nb);
  EXPECT_EQ(nb, 6);  // root→spine, spine→neck, spine→arm, neck→head, helpers of arm and head
  EXPECT_EQ(c.top_k(), 3);
  EXPECT_GT(p.subdivision_levels, 0);
  for (const auto& t : {c.positions, c.topk_distance, c.targets, c.bone_weights, c.bones})
    EXPECT_EQ(t.scalar_type(), torch::kFloat32);
  for (const auto& t : {c.topk_index, c.bone_joints, c.one_ring, c.geodesic})
    EXPECT_EQ(t.scalar_type(), torch::kInt64);
  EXPECT_EQ(c.positions.sizes(), (std::vector<std::int64_t>{nv, 3}));
  EXPECT_EQ(c.bone_weights.sizes(), (std::vector<std::int64_t>{nv, nb}));
  EXPECT_EQ(c.bones.sizes(), (std::vector<std::int64_t>{nb, 6}));
  EXPECT_EQ(c.one_ring.size(0), p.one_ring_edges.rows());
  EXPECT_EQ(c.geodesic.size(0), p.geodesic_edges.rows());
  EXPECT_EQ(c.positions[5][1].item<float>(), static_cast<float>(p.V(5, 1)));

  const auto& d = p.distances.at("euclidean");
  for (Eigen::Index v = 0; v < nv; v += 17) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(c.topk_index[v][k].item<std::int64_t>(), d.topk_index(v, k));
      EXPECT_EQ(c.topk_distance[v][k].item<float>(), d.topk_distance(v, k));
    }
  }
  // Targets: the stored candidate weights renormalised per row.
  const torch::Tensor sums = c.targets.sum(1);
  EXPECT_TRUE(torch::allclose(sums, torch::ones_like(sums), 1e-5, 1e-6));
  const float raw0 = d.targets(0, 0), raw_sum = d.targets.row(0).sum();
  EXPECT_NEAR(c.targets[0][0].item<float>(), raw0 / raw_sum, 1e-6);

  // Full bone weights: rows sum to 1, and agree with the preprocessing's rule and its targets.
  const torch::Tensor bsums = c.bone_weights.sum(1);
  EXPECT_TRUE(torch::allclose(bsums, torch::ones_like(bsums), 1e-5, 1e-6));
  EXPECT_TRUE(torch::all(c.bone_weights >= 0).item<bool>());
  EXPECT_TRUE(torch::allclose(c.bone_weights.gather(1, c.topk_index),
                              torch::from_blob(const_cast<float*>(d.targets.data()), {nv, 3}),
                              1e-6, 1e-6));

  // Bone attribute [start, end] and joints.
  for (std::int64_t b = 0; b < nb; ++b) {
    const int s = p.bones(b, 0), e = p.bones(b, 1);
    EXPECT_EQ(c.bone_joints[b][0].item<std::int64_t>(), s);
    EXPECT_EQ(c.bones[b][0].item<float>(), static_cast<float>(p.joints(s, 0)));
    EXPECT_EQ(c.bones[b][4].item<float>(), static_cast<float>(p.joints(e, 1)));
  }

  // The Laplacian: sparse COO with the stored triplets.
  ASSERT_TRUE(c.laplacian.is_sparse());
  EXPECT_EQ(c.laplacian.sizes(), (std::vector<std::int64_t>{nv, nv}));
  const torch::Tensor dense = c.laplacian.to_dense();
  for (std::size_t n = 0; n < p.laplacian_values.size(); n += 11) {
    EXPECT_FLOAT_EQ(dense[p.laplacian_indices(n, 0)][p.laplacian_indices(n, 1)].item<float>(),
                    static_cast<float>(p.laplacian_values[n]));
  }
  EXPECT_NEAR(dense.sum().item<float>(), 0.0f, 1e-3);  // L = D − A: rows sum to 0
}

TEST(ToTensors, TargetsWithoutCandidateWeightStayZero) {
  data::PreparedCharacter p = testing::tiny_character("tiny");
  auto& d = p.distances.at("euclidean");
  d.targets << 0.25f, 0.25f, 0.5f, 0.0f, 0.0f, 0.0f, 0.1f, 0.3f;
  const data::CharacterTensors c = data::to_tensors(p, "euclidean");
  EXPECT_FLOAT_EQ(c.targets[0][0].item<float>(), 0.5f);
  EXPECT_FLOAT_EQ(c.targets[1][0].item<float>(), 1.0f);
  EXPECT_FLOAT_EQ(c.targets[2][0].item<float>(), 0.0f);
  EXPECT_FLOAT_EQ(c.targets[2][1].item<float>(), 0.0f);
  EXPECT_FLOAT_EQ(c.targets[3][1].item<float>(), 0.75f);
  // Vertex 1 (0.25 root, 0.75 a): root's bones are 0 (→a) and 2 (→b); a's only bone is 1.
  EXPECT_FLOAT_EQ(c.bone_weights[1][1].item<float>(), 0.75f);
  EXPECT_FLOAT_EQ(c.bone_weights[1][0].item<float>() + c.bone_weights[1][2].item<float>(), 0.25f);
}

TEST(ToTensors, MissingDistanceTypeNamesTheCharacterAndWhatItHas) {
  const data::PreparedCharacter p = testing::tiny_character("tiny");
  expect_error<IoError>([&] { data::to_tensors(p, "hollow_dist"); },
                        {"character 'tiny' has no distance type 'hollow_dist'",
                         "it was prepared with: euclidean"});
}

TEST(ScatterToBones, PutsEachCandidateAtItsBoneAndIsDifferentiable) {
  const torch::Tensor index = torch::tensor({{2, 0}, {1, 3}}, torch::kInt64);
  const torch::Tensor pred = torch::tensor({{0.7f, 0.3f}, {0.4f, 0.6f}}).requires_grad_(true);
  const torch::Tensor out = data::scatter_to_bones(pred, index, 4);
  const torch::Tensor expected = torch::tensor({{0.3f, 0.0f, 0.7f, 0.0f}, {0.0f, 0.4f, 0.0f, 0.6f}});
  EXPECT_TRUE(torch::equal(out.detach(), expected));
  const torch::Tensor r = torch::arange(8, torch::kFloat32).reshape({2, 4});
  (out * r).sum().backward();
  EXPECT_TRUE(torch::equal(pred.grad(), r.gather(1, index)));  // d/dpred = R at the candidates
}

TEST(ScatterToBones, RejectsBadArguments) {
  const torch::Tensor pred = torch::full({2, 2}, 0.5f);
  const torch::Tensor index = torch::tensor({{0, 1}, {1, 2}}, torch::kInt64);
  expect_error<c10::Error>([&] { data::scatter_to_bones(pred, index, 2); },
                           {"outside [0, 2)"});
  expect_error<c10::Error>([&] { data::scatter_to_bones(pred, index.to(torch::kInt32), 3); },
                           {"int64"});
  expect_error<c10::Error>([&] { data::scatter_to_bones(pred, index.narrow(1, 0, 1), 3); },
                           {"pred is [2, 2] but topk_index is [2, 1]"});
  expect_error<c10::Error>([&] { data::scatter_to_bones(pred, index, 1); },
                           {"2 candidates per vertex but only 1 bones"});
}

TEST(CandidatesForModel, PadsASmallSkeletonsCandidatesWithTheNearestAndRefusesOtherCounts) {
  const data::CharacterTensors three = data::to_tensors(testing::prepared_tube(1), "euclidean");
  // As many candidates as the model reads: the same tensors.
  const data::CharacterTensors same = data::candidates_for_model(three, 3, "m");
  EXPECT_TRUE(same.topk_index.is_same(three.topk_index));

  // One candidate per bone (6), read by a K = 8 model: columns 6 and 7 repeat column 0.
  const data::CharacterTensors six = data::to_tensors(testing::prepared_tube(1, 8), "euclidean");
  ASSERT_EQ(six.top_k(), six.num_bones());
  const data::CharacterTensors padded = data::candidates_for_model(six, 8, "m");
  ASSERT_EQ(padded.top_k(), 8);
  EXPECT_TRUE(torch::equal(padded.topk_index.narrow(1, 0, 6), six.topk_index));
  EXPECT_TRUE(torch::equal(padded.topk_distance.narrow(1, 0, 6), six.topk_distance));
  for (std::int64_t j = 6; j < 8; ++j) {
    EXPECT_TRUE(torch::equal(padded.topk_index.select(1, j), six.topk_index.select(1, 0)));
    EXPECT_TRUE(torch::equal(padded.topk_distance.select(1, j), six.topk_distance.select(1, 0)));
  }
  EXPECT_EQ(padded.targets.size(1), 6);  // the loss compares the model's #V×6 with these

  // Fewer candidates than K on a character with more bones than that: a mismatch.
  expect_error<c10::Error>([&] { data::candidates_for_model(three, 4, "the model"); },
                           {"the model", "top_k = 4", "'tube_1'", "3 candidate", "6 bones"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

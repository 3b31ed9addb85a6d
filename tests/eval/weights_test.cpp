// The metrics' shared helpers: pruning, bone → joint weights (against the preprocessing's
// joint → bone rule), and the argument checks every metric runs first.

#include "framework/eval/weights.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "framework/core/error.hpp"
#include "framework/data/preprocess.hpp"
#include "tests/eval/eval_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab::eval {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using skinlab::testing::weights;

RowMatrixXd rows(std::initializer_list<std::initializer_list<double>> values) {
  RowMatrixXd m(values.size(), values.begin()->size());
  Eigen::Index i = 0;
  for (const auto& row : values) {
    Eigen::Index j = 0;
    for (double x : row) m(i, j++) = x;
    ++i;
  }
  return m;
}

TEST(PruneRows, ByHand) {
  RowMatrixXd W = rows({{0.6, 0.3, 0.1}, {0.2, 0.2, 0.0}, {0, 0, 0}, {0.5, 0.1, 0.4}});
  prune_rows(W, 0.25);
  // Row 0: 0.1 < 0.15 goes, (0.6, 0.3)/0.9. Row 1: ties at the maximum stay. Row 2: all-zero
  // stays zero. Row 3: 0.1 < 0.125 goes.
  const RowMatrixXd expected =
      rows({{2.0 / 3, 1.0 / 3, 0}, {0.5, 0.5, 0}, {0, 0, 0}, {5.0 / 9, 0, 4.0 / 9}});
  EXPECT_TRUE(W.isApprox(expected, 1e-15)) << W;
  RowMatrixXd again = W;
  prune_rows(again, 0.25);
  EXPECT_EQ(again, W);  // idempotent
  RowMatrixXd unchanged = rows({{0.6, 0.3, 0.1}});
  prune_rows(unchanged, 0.0);
  EXPECT_EQ(unchanged, rows({{0.6, 0.3, 0.1}}));
  prune_rows(unchanged, 1.0);
  EXPECT_EQ(unchanged, rows({{1, 0, 0}}));
  EXPECT_THROW(prune_rows(unchanged, 1.5), skinlab::Error);  // infer/map_back.hpp
}

TEST(JointWeights, SumsTheBonesOfEachStartJoint) {
  // Bones (0→1), (0→2), (1→1), (2→2): bones 0 and 1 both move with joint 0.
  const RowMatrixXi bones = (RowMatrixXi(4, 2) << 0, 1, 0, 2, 1, 1, 2, 2).finished();
  const RowMatrixXd W = rows({{0.25, 0.25, 0.5, 0}, {0, 0, 0, 1}});
  const Eigen::MatrixXd J = Eigen::MatrixXd(joint_weights(W, bones, 3));
  EXPECT_EQ(J, (Eigen::MatrixXd(2, 3) << 0.5, 0.5, 0, 0, 0, 1).finished());
  expect_error<c10::Error>([&] { joint_weights(W, bones, 2); },
                           {"bone 3 starts at joint 2", "outside [0, 2)"});
}

TEST(JointWeights, UndoesThePreprocessingBoneRule) {
  // Artist joint weights → bone weights (data::bone_weights, which gives a branching joint's
  // weight to its nearest bone) → joint weights again.
  geometry::Skeleton s;
  s.names = {"hips", "spine", "l_arm", "r_arm", "neck"};
  s.parents = {-1, 0, 1, 1, 1};  // spine branches into three bones
  s.positions = Eigen::MatrixXd::Random(5, 3);
  const auto bones = s.bones();
  RowMatrixXi B(static_cast<Eigen::Index>(bones.size()), 2);
  for (std::size_t b = 0; b < bones.size(); ++b)
    B.row(static_cast<Eigen::Index>(b)) << bones[b].start, bones[b].end;
  geometry::SparseWeights W(6, 5);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(0, 1);
  for (int v = 0; v < 6; ++v) {
    const double a = u(rng), b = u(rng);
    W.insert(v, v % 5) = a / (a + b);
    W.insert(v, (v + 1) % 5) = b / (a + b);
  }
  W.makeCompressed();
  const Eigen::MatrixXd D = Eigen::MatrixXd::Random(6, B.rows()).cwiseAbs();
  const RowMatrixXd bone_level = data::bone_weights(W, s, D);
  EXPECT_TRUE(Eigen::MatrixXd(joint_weights(bone_level, B, 5)).isApprox(Eigen::MatrixXd(W), 1e-15));
}

TEST(ReadWeights, ShapeErrorsNameBothShapes) {
  const torch::Tensor a = weights({{1, 0}, {0, 1}, {0.5, 0.5}});
  const torch::Tensor b = weights({{1, 0, 0}, {0, 1, 0}, {0.5, 0.5, 0}});
  expect_error<c10::Error>(
      [&] {
        read_weights({a, b}, "avg_l1");
      },
      {"metric 'avg_l1'", "prediction shape [3, 2]", "target shape [3, 3]"});
  expect_error<c10::Error>(
      [&] {
        read_weights({a.flatten(), a.flatten()}, "avg_l1");
      },
      {"must be #V×#B", "[6] and [6]"});
  expect_error<c10::Error>(
      [&] {
        read_weights({a, torch::Tensor()}, "avg_l1");
      },
      {"needs both a prediction and a target"});
  expect_error<c10::Error>(
      [&] {
        read_weights({a.to(torch::kInt64), a.to(torch::kInt64)}, "avg_l1");
      },
      {"floating-point"});
  const auto arm = testing::two_joint_arm("hero");
  const torch::Tensor two_rows = weights({{1, 0}, {0, 1}});
  expect_error<c10::Error>(
      [&] {
        read_weights({two_rows, two_rows, &arm}, "precision_recall");
      },
      {"metric 'precision_recall' (character 'hero')", "weights are [2, 2]", "#V×#B = [3, 2]"});
}

TEST(ReadWeights, RejectsNegativeAndNonFiniteWeights) {
  const torch::Tensor good = weights({{1, 0}, {0, 1}});
  expect_error<c10::Error>(
      [&] {
        read_weights({weights({{1, 0}, {-0.5, 1.5}}), good}, "avg_l1");
      },
      {"predicted weight of vertex 1 on bone 0 is -0.5"});
  torch::Tensor nan = good.clone();
  nan[0][1] = std::numeric_limits<float>::quiet_NaN();
  expect_error<c10::Error>(
      [&] {
        read_weights({good, nan}, "avg_l1");
      },
      {"target weight of vertex 0 on bone 1 is nan"});
  const WeightPair pair = read_weights({good.to(torch::kFloat64).requires_grad_(), good}, "x");
  EXPECT_EQ(pair.pred, rows({{1, 0}, {0, 1}}));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::eval

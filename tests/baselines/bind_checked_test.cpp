// binders::bind_checked, the one place every caller of a binder (the evaluator's rows, the
// dataset's stored priors, `predict --binder`) goes through: a result that breaks the Binder
// contract (wrong shape, a negative entry, a row not summing to 1) is an Error naming the binder,
// the character and the first bad vertex; a valid result comes back unchanged.

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "framework/binders/binder.hpp"
#include "framework/core/error.hpp"
#include "tests/baselines/binder_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::Chain;
using testing::expect_error;

/// A binder that returns whatever `make` gives for the mesh's vertex count and the skeleton's bone
/// count: all weight on bone 0 unless a test changes it.
class ScriptedBinder final : public binders::Binder {
 public:
  using Make = std::function<Eigen::MatrixXd(Eigen::Index vertices, Eigen::Index bones)>;
  explicit ScriptedBinder(Make make) : make_(std::move(make)) {}
  Eigen::MatrixXd bind(const geometry::Mesh& mesh,
                       const geometry::Skeleton& skeleton) const override {
    return make_(mesh.V.rows(), static_cast<Eigen::Index>(skeleton.bones().size()));
  }

 private:
  Make make_;
};

Eigen::MatrixXd on_bone_zero(Eigen::Index vertices, Eigen::Index bones) {
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(vertices, bones);
  W.col(0).setOnes();
  return W;
}

TEST(BindChecked, AValidResultComesBackUnchanged) {
  const Chain c = testing::chain();
  const ScriptedBinder binder(on_bone_zero);
  const Eigen::MatrixXd W = binders::bind_checked(binder, c.mesh, c.skeleton, "binder 'x' on 'chain'");
  EXPECT_EQ(W.rows(), c.mesh.V.rows());
  EXPECT_EQ(W.cols(), 4);  // three bones and the leaf's helper
  EXPECT_TRUE(W.isApprox(on_bone_zero(W.rows(), W.cols())));
}

TEST(BindChecked, AWrongShapeNamesBothShapes) {
  const Chain c = testing::chain();
  const ScriptedBinder binder([](Eigen::Index v, Eigen::Index b) { return on_bone_zero(v, b - 1); });
  const auto v = std::to_string(c.mesh.V.rows());
  expect_error<Error>(
      [&] { binders::bind_checked(binder, c.mesh, c.skeleton, "binder 'x' on 'chain'"); },
      {"binder 'x' on 'chain'", "returned " + v + "×3 weights, expected " + v + "×4"});
}

TEST(BindChecked, ANegativeEntryOrABadSumNamesTheFirstBadVertex) {
  const Chain c = testing::chain();
  const ScriptedBinder negative([](Eigen::Index v, Eigen::Index b) {
    Eigen::MatrixXd W = on_bone_zero(v, b);
    W(7, 0) = 1.5;
    W(7, 1) = -0.5;  // sums to 1, but not a weight
    return W;
  });
  expect_error<Error>(
      [&] { binders::bind_checked(negative, c.mesh, c.skeleton, "binder 'x' on 'chain'"); },
      {"binder 'x' on 'chain'", "vertex 7", "min -0.5"});
  const ScriptedBinder unnormalised([](Eigen::Index v, Eigen::Index b) {
    Eigen::MatrixXd W = on_bone_zero(v, b);
    W(20, 1) = 0.5;
    W(30, 0) = 0.0;  // the later bad row is not the one named
    return W;
  });
  expect_error<Error>(
      [&] { binders::bind_checked(unnormalised, c.mesh, c.skeleton, "binder 'x' on 'chain'"); },
      {"vertex 20 has weights summing to 1.5"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

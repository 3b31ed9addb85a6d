// `skinlab-predict`'s whole path without libtorch (infer/eigen_predictor.hpp): the bundled
// model's parameters.h5 on the bundled 0 A.D. characters it was tested on, from the game files
// to per-joint weights at the input's vertices. This area links no libtorch, so the sanitized
// CI step runs it (tests/CMakeLists.txt, SKINLAB_SANITIZE_AREAS); the comparison with the
// libtorch forward pass is tests/predict/eigen_network_test.cpp.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>
#include <map>

#include "framework/core/atomic_file.hpp"
#include "framework/core/registry.hpp"
#include "framework/data/source.hpp"
#include "framework/infer/eigen_predictor.hpp"
#include "framework/infer/model_dir.hpp"
#include "tests/bundled_dataset.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;

/// Every row of `w` is a distribution: finite, non-negative, summing to 1.
void expect_distributions(const data::RowMatrixXf& w, const char* what) {
  ASSERT_GT(w.rows(), 0) << what;
  ASSERT_TRUE(w.allFinite()) << what;
  EXPECT_GE(w.minCoeff(), 0.0f) << what;
  const Eigen::VectorXf sums = w.rowwise().sum();
  EXPECT_LE((sums.array() - 1.0f).abs().maxCoeff(), 1e-4f) << what;
}

/// The paper's L1 (Sec. 4.3): the mean over vertices of Σ_b |w_vb − w*_vb|.
double mean_l1(const data::RowMatrixXf& w, const data::RowMatrixXf& truth) {
  return (w - truth).cwiseAbs().rowwise().sum().mean();
}

TEST(EigenPredict, BundledModelSkinsItsTestCharacters) {
  const fs::path dir = infer::default_model();
  const infer::EigenPredictor model = infer::EigenPredictor::load(dir);

  const nlohmann::json eval = nlohmann::json::parse(read_file(dir / "eval_test.json"));
  std::map<std::string, double> recorded_l1;  // the model's evaluation (skinlab eval, libtorch)
  for (const auto& c : eval.at("per_character"))
    recorded_l1[c.at("character").get<std::string>()] =
        c.at("values").at("avg_l1").get<double>();
  int predicted = 0;
  for (const auto& source : testing::bundled_test_characters(dir)) {
    SCOPED_TRACE(source.character.name);
    infer::PredictOptions options;
    options.up = source.up;
    const infer::Prediction p = model.predict(source.character, options);
    const data::PreparedCharacter& prepared = p.prepared;
    const Eigen::Index num_vertices = prepared.num_vertices();
    const Eigen::Index num_bones = prepared.num_bones();

    ASSERT_EQ(p.candidates.rows(), num_vertices);
    ASSERT_EQ(p.candidates.cols(), static_cast<Eigen::Index>(model.network().top_k()));
    expect_distributions(p.candidates, "network output");
    ASSERT_EQ(p.prepared_weights.rows(), num_vertices);
    ASSERT_EQ(p.prepared_weights.cols(), num_bones);
    expect_distributions(p.prepared_weights, "pruned weights");
    ASSERT_EQ(p.source_weights.rows(), static_cast<Eigen::Index>(source.character.mesh.num_vertices()));
    expect_distributions(p.source_weights, "weights at the input's vertices");

    // Weight only on a vertex's candidate bones, and none below the pruning threshold.
    const data::RowMatrixXi& topk = prepared.distances.at(model.distance()).topk_index;
    for (Eigen::Index v = 0; v < num_vertices; ++v) {
      const float largest = p.prepared_weights.row(v).maxCoeff();
      for (Eigen::Index b = 0; b < num_bones; ++b) {
        const float w = p.prepared_weights(v, b);
        if (w == 0.0f) continue;
        bool candidate = false;
        for (Eigen::Index k = 0; k < topk.cols(); ++k) candidate |= topk(v, k) == b;
        ASSERT_TRUE(candidate) << "vertex " << v << " bone " << b;
        ASSERT_GE(w, 0.25f * largest - 1e-6f) << "vertex " << v << " bone " << b;
      }
    }

    // Deterministic: a second prediction gives the same bits.
    const infer::Prediction again = model.predict(source.character, options);
    EXPECT_TRUE(again.prepared_weights == p.prepared_weights);

    // A trained network: closer to the artist's weights than spreading every vertex evenly
    // over its candidates, and most vertices' largest weight on the artist's largest bone.
    ASSERT_EQ(p.prepared_truth.rows(), num_vertices);
    data::RowMatrixXf even = data::RowMatrixXf::Zero(num_vertices, num_bones);
    for (Eigen::Index v = 0; v < num_vertices; ++v)
      for (Eigen::Index k = 0; k < topk.cols(); ++k)
        even(v, topk(v, k)) = 1.0f / static_cast<float>(topk.cols());
    const double l1 = mean_l1(p.prepared_weights, p.prepared_truth);
    const double even_l1 = mean_l1(even, p.prepared_truth);
    Eigen::Index agree = 0;
    for (Eigen::Index v = 0; v < num_vertices; ++v) {
      Eigen::Index mine = 0, artist = 0;
      p.prepared_weights.row(v).maxCoeff(&mine);
      p.prepared_truth.row(v).maxCoeff(&artist);
      agree += mine == artist;
    }
    const double dominant = static_cast<double>(agree) / static_cast<double>(num_vertices);
    std::cout << source.character.name << ": " << num_vertices << " prepared vertices, L1 "
              << l1 << " (even over candidates " << even_l1 << "), dominant bone " << dominant
              << "\n";
    EXPECT_LT(l1, 0.8 * even_l1);
    // The same L1 as the model's recorded evaluation of this character (eval_test.json,
    // avg_l1 with prune 0.25, made by libtorch from the dataset file): this path from the
    // game files agrees with it.
    EXPECT_NEAR(l1, recorded_l1.at(source.character.name), 1e-4);
    EXPECT_GT(dominant, 0.6);
    ++predicted;
  }
  EXPECT_GE(predicted, 2)
      << "at least two of the bundled model's test characters are in the bundled 0 A.D. subset";
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

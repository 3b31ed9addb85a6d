#pragma once
// Shared by the DenseGATs tests: the bundled real 0 A.D. bipeds (configs/datasets/
// zeroad_bipeds_bundled.yaml: f_dress, m_armor_pants, m_tunic_short and their game clips),
// prepared once per test suite into a scratch directory.

#include <gtest/gtest.h>

#include <string>

#include "experiments/densegats/corrective_data.hpp"
#include "framework/core/config.hpp"
#include "framework/data/dataset_file.hpp"
#include "tests/bundled_dataset.hpp"
#include "tests/test_util.hpp"

namespace skinlab::densegats {

/// The bundled bipeds, prepared once for the whole suite.
class BundledBipeds : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new skinlab::testing::TempDir();
    file_ = (*dir_ / "bipeds.h5").string();
    dataset_ = new data::Dataset(
        skinlab::testing::prepare_bundled("configs/datasets/zeroad_bipeds_bundled.yaml", file_));
  }
  static void TearDownTestSuite() {
    delete dataset_;
    delete dir_;
  }
  static CorrectiveOptions options(int stride = 8) {
    CorrectiveOptions o;
    o.frame_stride = stride;
    return o;
  }
  static inline skinlab::testing::TempDir* dir_ = nullptr;
  static inline std::string file_;
  static inline data::Dataset* dataset_ = nullptr;
};

}  // namespace skinlab::densegats

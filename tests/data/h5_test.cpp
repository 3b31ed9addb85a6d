#include "framework/data/h5.hpp"

#include <gtest/gtest.h>

#include "framework/core/error.hpp"
#include "tests/test_util.hpp"

namespace skinlab::data {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using skinlab::testing::TempDir;

TEST(H5, RoundTripsMatricesGroupsAndAttributes) {
  TempDir dir;
  RowMatrixXd d(2, 3);
  d << 1, 2, 3, 4, 5, 6.5;
  RowMatrixXi i(3, 1);
  i << 7, -8, 9;
  RowMatrixXf empty(0, 4);
  {
    H5Writer w(dir / "a.h5");
    w.write("chars/hero/D", d);
    w.write("chars/hero/F", i);
    w.write("empty", empty);
    w.write_attribute("distance", "hollow_dist");
    w.commit();
  }
  H5Reader r(dir / "a.h5");
  EXPECT_TRUE(r.has("chars/hero/D"));
  EXPECT_FALSE(r.has("chars/villain"));
  EXPECT_EQ(r.read_double("chars/hero/D"), d);
  EXPECT_EQ(r.read_int("chars/hero/F"), i);
  EXPECT_EQ(r.read_float("empty").cols(), 4);
  EXPECT_EQ(r.read_double("chars/hero/F")(1, 0), -8.0);  // converted on read
  EXPECT_EQ(r.read_attribute("distance"), "hollow_dist");
  expect_error<IoError>([&] { r.read_double("nope"); }, {"a.h5: no dataset 'nope'"});
  expect_error<IoError>([&] { r.read_attribute("nope"); }, {"no attribute 'nope'"});
}

TEST(H5, UncommittedWriteLeavesTheOldFile) {
  TempDir dir;
  RowMatrixXd one = RowMatrixXd::Ones(1, 1);
  {
    H5Writer w(dir / "a.h5");
    w.write("x", one);
    w.commit();
  }
  {
    H5Writer w(dir / "a.h5");
    w.write("x", RowMatrixXd(RowMatrixXd::Zero(5, 5)));
    // no commit: as if the process died here
  }
  EXPECT_EQ(H5Reader(dir / "a.h5").read_double("x"), one);
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 1u);
}

TEST(H5, BadFilesAreNamed) {
  TempDir dir;
  expect_error<IoError>([&] { H5Reader(dir / "absent.h5"); }, {"absent.h5: file does not exist"});
  const auto text = dir.write("text.h5", "not hdf5");
  expect_error<IoError>([&] { H5Reader r(text); }, {"text.h5: not an HDF5 file"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::data

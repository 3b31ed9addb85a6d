#include "framework/data/h5.hpp"

#include <H5Cpp.h>
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

TEST(H5, StringsRoundTripAsFixedLength) {
  TempDir dir;
  const std::vector<std::string> names = {"", "root", "Bip01 L Forearm", "\u00e9paule \u2192"};
  std::vector<std::string> many;  // large enough to be chunked and compressed
  for (int k = 0; k < 2000; ++k) many.push_back("reason " + std::to_string(k));
  {
    H5Writer w(dir / "s.h5");
    w.write_strings("names", names);
    w.write_strings("none", {});
    w.write_strings("many", many);
    w.write_attribute("/", "empty", std::string());
    w.write_attribute("/", "text", std::string("line 1\nline 2 \u00e9"));
    w.commit();
  }
  H5Reader r(dir / "s.h5");
  EXPECT_EQ(r.read_strings("names"), names);
  EXPECT_TRUE(r.read_strings("none").empty());
  EXPECT_EQ(r.read_strings("many"), many);
  EXPECT_EQ(r.read_attribute("/", "empty"), "");
  EXPECT_EQ(r.read_attribute("/", "text"), "line 1\nline 2 \u00e9");
}

TEST(H5, SizesAFileCannotHoldAreRejectedBeforeReading) {
  TempDir dir;
  {
    H5Writer w(dir / "big.h5");
    // 2^20 × 2^20 floats (4 TiB) claimed by a dataspace whose data was never written: what a
    // damaged dataspace looks like to the reader.
    w.write("small", std::vector<float>{1, 2});
    w.commit();
  }
  {
    const hid_t f = H5Fopen((dir / "big.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const hsize_t dims[2] = {hsize_t{1} << 20, hsize_t{1} << 20};
    const hid_t space = H5Screate_simple(2, dims, nullptr);
    const hid_t set = H5Dcreate2(f, "huge", H5T_NATIVE_FLOAT, space, H5P_DEFAULT, H5P_DEFAULT,
                                 H5P_DEFAULT);
    H5Dclose(set);
    H5Sclose(space);
    H5Fclose(f);
  }
  expect_error<IoError>([&] { H5Reader(dir / "big.h5").read_float("huge"); },
                        {"big.h5", "dataset 'huge'", "1048576×1048576", "more than the file can hold"});
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

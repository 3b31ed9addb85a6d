#pragma once
/// \file
/// Small HDF5 layer over the C++ API: Eigen matrices as 2-D datasets (row-major on disk, so
/// `h5dump` shows them as they print), strings as attributes, groups by '/' in the name. Writes
/// go to a temporary file renamed into place on `commit()`, so a crash never leaves a partial
/// file under the target name. HDF5 errors become IoError naming the file and the dataset.

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/core/atomic_file.hpp"

namespace H5 {
class H5File;
}

namespace skinlab::data {

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixXf = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixXi = Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

class H5Writer {
 public:
  /// Starts writing `target` (through a temporary file in the same directory).
  explicit H5Writer(const std::filesystem::path& target);
  ~H5Writer();
  H5Writer(const H5Writer&) = delete;
  H5Writer& operator=(const H5Writer&) = delete;

  /// Writes a 2-D dataset; intermediate groups in `name` ("a/b/c") are created.
  void write(const std::string& name, const RowMatrixXd& matrix);
  void write(const std::string& name, const RowMatrixXf& matrix);
  void write(const std::string& name, const RowMatrixXi& matrix);
  /// Writes a string attribute on the root group (`name` without '/').
  void write_attribute(const std::string& name, const std::string& value);
  /// Closes the file and renames it into place.
  void commit();

 private:
  AtomicPath out_;
  std::unique_ptr<H5::H5File> file_;
};

class H5Reader {
 public:
  explicit H5Reader(const std::filesystem::path& file);
  ~H5Reader();
  bool has(const std::string& name) const;
  RowMatrixXd read_double(const std::string& name) const;
  RowMatrixXf read_float(const std::string& name) const;
  RowMatrixXi read_int(const std::string& name) const;
  std::string read_attribute(const std::string& name) const;

 private:
  std::filesystem::path path_;
  std::unique_ptr<H5::H5File> file_;
};

}  // namespace skinlab::data

#pragma once
/// \file
/// Small HDF5 layer over the C++ API: Eigen matrices as 2-D datasets (row-major on disk, so
/// `h5dump` and h5py show them as they print), 1-D arrays, N-D float arrays, string lists, and
/// string, integer and number attributes on any group. Groups are created by '/' in the name.
///
/// Strings are fixed-length (null-padded UTF-8), never variable-length: variable-length data
/// lives in HDF5's global heap, and libhdf5 1.10.8 loops forever in H5HG_read on a damaged one.
/// The reader refuses a variable-length string by its datatype alone, before touching its data,
/// so no file reaches the global heap through this layer. Sizes a damaged file claims are
/// checked against the file's size before anything is allocated. Arrays of at least kChunkThreshold elements are chunked and
/// deflate-compressed (gzip level 4, which h5py and h5dump read without plug-ins).
///
/// Writes go to a temporary file renamed into place on `commit()`, so a crash never leaves a
/// partial file under the target name. HDF5 errors become IoError naming the file and the
/// dataset.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
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

/// Arrays with at least this many elements are stored chunked and deflate-compressed; smaller
/// ones contiguously (a chunk index costs more than it saves on a 3×4 matrix).
inline constexpr std::size_t kChunkThreshold = 1024;
/// Deflate (gzip) level of compressed arrays.
inline constexpr int kDeflateLevel = 4;

class H5Writer {
 public:
  /// Starts writing `target` (through a temporary file in the same directory). Arrays of at
  /// least kChunkThreshold elements are chunked and deflated at `deflate_level` (1–9); 0 stores
  /// everything contiguous and uncompressed (fast, for intermediate files).
  explicit H5Writer(const std::filesystem::path& target, int deflate_level = kDeflateLevel);
  ~H5Writer();
  H5Writer(const H5Writer&) = delete;
  H5Writer& operator=(const H5Writer&) = delete;

  /// Writes a 2-D dataset; intermediate groups in `name` ("a/b/c") are created.
  void write(const std::string& name, const RowMatrixXd& matrix);
  void write(const std::string& name, const RowMatrixXf& matrix);
  void write(const std::string& name, const RowMatrixXi& matrix);
  /// Writes a 1-D dataset.
  void write(const std::string& name, const std::vector<int>& values);
  void write(const std::string& name, const std::vector<float>& values);
  void write(const std::string& name, const std::vector<double>& values);
  /// Writes an N-D float32 dataset of shape `dims` from row-major `data` (prod(dims) values).
  void write(const std::string& name, const std::vector<std::size_t>& dims, const float* data);
  /// Writes a 1-D dataset of fixed-length (the longest entry's size, at least 1) null-padded
  /// UTF-8 strings; h5py reads them as `bytes` (`.asstr()` gives `str`).
  void write_strings(const std::string& name, const std::vector<std::string>& values);
  /// Creates a group (and its parents) if it does not exist.
  void create_group(const std::string& name);

  /// Writes a string attribute on the root group (`name` without '/'): a scalar fixed-length
  /// null-padded UTF-8 string of the value's size (at least 1); h5py reads it as `bytes`.
  void write_attribute(const std::string& name, const std::string& value);
  /// Attributes on the group or dataset `object` ("/" for the root; groups are created).
  void write_attribute(const std::string& object, const std::string& name,
                       const std::string& value);
  void write_attribute(const std::string& object, const std::string& name, std::int64_t value);
  void write_attribute(const std::string& object, const std::string& name, double value);
  /// Closes the file and renames it into place.
  void commit();

  const std::filesystem::path& target() const { return out_.target(); }

 private:
  AtomicPath out_;
  int deflate_level_;
  std::unique_ptr<H5::H5File> file_;
};

class H5Reader {
 public:
  /// Opens `file` read-only. Throws IoError naming the file if it does not exist or is not an
  /// HDF5 file (including a file truncated before its superblock). `older_writer_advice` ends
  /// the error for a variable-length string (what an older skinlab wrote), e.g. "written by an
  /// older skinlab: re-run `skinlab prepare`".
  explicit H5Reader(const std::filesystem::path& file, std::string older_writer_advice = {});
  ~H5Reader();
  /// True if the link `name` exists (every group on the way must exist too).
  bool has(const std::string& name) const;
  /// Dimensions of dataset `name`. Throws IoError naming file and dataset if it is missing.
  std::vector<std::size_t> shape(const std::string& name) const;
  /// Names of the links in group `name`, in HDF5's (alphabetical) order.
  std::vector<std::string> children(const std::string& name) const;

  /// 2-D datasets, converted from the stored numeric type.
  RowMatrixXd read_double(const std::string& name) const;
  RowMatrixXf read_float(const std::string& name) const;
  RowMatrixXi read_int(const std::string& name) const;
  /// 1-D datasets.
  std::vector<int> read_ints(const std::string& name) const;
  std::vector<float> read_floats(const std::string& name) const;
  std::vector<double> read_doubles(const std::string& name) const;
  /// Any-rank float dataset as row-major values; `dims` receives its shape.
  std::vector<float> read_float_array(const std::string& name,
                                      std::vector<std::size_t>& dims) const;
  /// 1-D fixed-length string dataset; a variable-length one is an IoError (its data unread).
  std::vector<std::string> read_strings(const std::string& name) const;

  /// String attribute on the root group (fixed-length; variable-length is an IoError).
  std::string read_attribute(const std::string& name) const;
  bool has_attribute(const std::string& object, const std::string& name) const;
  std::string read_attribute(const std::string& object, const std::string& name) const;
  std::int64_t read_int_attribute(const std::string& object, const std::string& name) const;
  double read_double_attribute(const std::string& object, const std::string& name) const;

  const std::filesystem::path& path() const { return path_; }

 private:
  [[noreturn]] void variable_length(const std::string& what) const;

  std::filesystem::path path_;
  std::string older_writer_advice_;
  std::unique_ptr<H5::H5File> file_;
};

}  // namespace skinlab::data

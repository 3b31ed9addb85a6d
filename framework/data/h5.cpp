#include "framework/data/h5.hpp"

#include <H5Cpp.h>

#include <algorithm>
#include <functional>
#include <numeric>

#include "framework/core/error.hpp"

namespace skinlab::data {

namespace {

/// The innermost description on HDF5's error stack (e.g. "truncated file: eof = ..."), which
/// says more than the C++ wrapper's "H5Fopen failed".
std::string hdf5_cause() {
  std::string cause;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_DOWNWARD,
      [](unsigned, const H5E_error2_t* e, void* out) -> herr_t {
        if (e->desc != nullptr && e->desc[0] != '\0') *static_cast<std::string*>(out) = e->desc;
        return 0;
      },
      &cause);
  return cause;
}

[[noreturn]] void rethrow(const std::filesystem::path& file, const std::string& what,
                          const H5::Exception& e) {
  std::string cause = hdf5_cause();
  if (cause.empty()) cause = e.getDetailMsg();
  throw IoError(file.string() + ": " + what + ": " + cause);
}

void ensure_groups(H5::H5File& file, const std::string& name, bool including_last) {
  std::size_t pos = name.find('/', 1);
  for (;; pos = name.find('/', pos + 1)) {
    const std::string group = pos == std::string::npos ? name : name.substr(0, pos);
    if (pos == std::string::npos && !including_last) return;
    if (!group.empty() && group != "/" && !file.nameExists(group)) file.createGroup(group);
    if (pos == std::string::npos) return;
  }
}

std::size_t product(const std::vector<hsize_t>& dims) {
  return std::accumulate(dims.begin(), dims.end(), std::size_t{1},
                         [](std::size_t a, hsize_t b) { return a * static_cast<std::size_t>(b); });
}

/// A fixed-length, null-padded UTF-8 string type of `width` bytes.
H5::StrType fixed_string_type(std::size_t width) {
  H5::StrType type(H5::PredType::C_S1, width);
  type.setCset(H5T_CSET_UTF8);
  type.setStrpad(H5T_STR_NULLPAD);
  return type;
}

/// The most bytes a dataset or attribute of `file` can hold in memory: its file size times
/// deflate's largest ratio (about 1:1032), plus 1 MiB. A damaged dataspace or datatype claiming
/// more is rejected before anything is allocated (instead of std::bad_alloc, or minutes of
/// zero-filling).
std::size_t plausible_bytes(const std::filesystem::path& file) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  return (ec ? 0 : static_cast<std::size_t>(size)) * 1100 + (std::size_t{1} << 20);
}

/// prod(dims) × element_size, or throws IoError naming the file and `what` when it overflows or
/// exceeds plausible_bytes.
std::size_t checked_bytes(const std::filesystem::path& file, const std::string& what,
                          const std::vector<hsize_t>& dims, std::size_t element_size) {
  const std::size_t limit = plausible_bytes(file);
  std::size_t bytes = std::max<std::size_t>(1, element_size);
  for (const hsize_t d : dims) {
    if (d != 0 && bytes > limit / static_cast<std::size_t>(d)) {
      std::string shape;
      for (const hsize_t e : dims) shape += (shape.empty() ? "" : "×") + std::to_string(e);
      throw IoError(file.string() + ": " + what + " claims " + shape + " elements of " +
                    std::to_string(element_size) +
                    " bytes, more than the file can hold (damaged file)");
    }
    bytes *= static_cast<std::size_t>(d);
  }
  return bytes;
}

/// Chunked + deflate above kChunkThreshold: chunks span whole trailing dimensions and about
/// 64 Ki elements of the first, so a reader of one row (one vertex) decompresses little.
H5::DSetCreatPropList creation_properties(const std::vector<hsize_t>& dims, int level) {
  H5::DSetCreatPropList props;
  if (level == 0 || dims.empty() || product(dims) < kChunkThreshold) return props;
  std::vector<hsize_t> chunk = dims;
  const std::size_t rest = product(dims) / static_cast<std::size_t>(dims[0]);
  chunk[0] =
      std::max<hsize_t>(1, std::min<hsize_t>(dims[0], 65536 / std::max<std::size_t>(1, rest)));
  props.setChunk(static_cast<int>(chunk.size()), chunk.data());
  props.setDeflate(static_cast<unsigned>(level));
  return props;
}

template <class T>
void write_array(H5::H5File& file, const std::filesystem::path& path, const std::string& name,
                 const std::vector<hsize_t>& dims, const T* data, const H5::PredType& type,
                 int level) {
  try {
    ensure_groups(file, name, false);
    H5::DataSpace space(static_cast<int>(dims.size()), dims.data());
    H5::DataSet set = file.createDataSet(name, type, space, creation_properties(dims, level));
    if (product(dims) > 0) set.write(data, type);
  } catch (const H5::Exception& e) {
    rethrow(path, "cannot write dataset '" + name + "'", e);
  }
}

template <class Matrix>
void write_matrix(H5::H5File& file, const std::filesystem::path& path, const std::string& name,
                  const Matrix& m, const H5::PredType& type, int level) {
  write_array(file, path, name, {static_cast<hsize_t>(m.rows()), static_cast<hsize_t>(m.cols())},
              m.data(), type, level);
}

H5::DataSet open_dataset(H5::H5File& file, const std::filesystem::path& path,
                         const std::string& name, std::vector<hsize_t>& dims) {
  H5::DataSet set = file.openDataSet(name);
  H5::DataSpace space = set.getSpace();
  const int rank = space.getSimpleExtentNdims();
  dims.assign(static_cast<std::size_t>(std::max(rank, 0)), 0);
  if (rank > 0) space.getSimpleExtentDims(dims.data());
  (void)path;
  return set;
}

bool link_exists(H5::H5File& file, const std::string& name) {
  // H5Lexists fails (rather than returning false) when an intermediate group is missing.
  std::size_t pos = name.find('/', 1);
  for (;; pos = name.find('/', pos + 1)) {
    const std::string prefix = pos == std::string::npos ? name : name.substr(0, pos);
    if (!prefix.empty() && prefix != "/" && !file.nameExists(prefix)) return false;
    if (pos == std::string::npos) return true;
  }
}

template <class T>
std::vector<T> read_values(H5::H5File& file, const std::filesystem::path& path,
                           const std::string& name, int rank, const H5::PredType& type,
                           std::vector<std::size_t>* dims_out = nullptr) {
  try {
    // Inside the try: on a damaged file the lookup itself fails with an H5::Exception.
    if (!link_exists(file, name)) throw IoError(path.string() + ": no dataset '" + name + "'");
    std::vector<hsize_t> dims;
    H5::DataSet set = open_dataset(file, path, name, dims);
    if (rank >= 0 && static_cast<int>(dims.size()) != rank) {
      throw IoError(path.string() + ": dataset '" + name + "' has rank " +
                    std::to_string(dims.size()) + ", expected " + std::to_string(rank));
    }
    const H5T_class_t cls = set.getTypeClass();
    if (cls != H5T_INTEGER && cls != H5T_FLOAT) {
      throw IoError(path.string() + ": dataset '" + name + "' is not numeric");
    }
    checked_bytes(path, "dataset '" + name + "'", dims, std::max(sizeof(T), set.getDataType().getSize()));
    std::vector<T> values(product(dims));
    if (!values.empty()) set.read(values.data(), type);  // converts from the stored type
    if (dims_out != nullptr) dims_out->assign(dims.begin(), dims.end());
    return values;
  } catch (const H5::Exception& e) {
    rethrow(path, "cannot read dataset '" + name + "'", e);
  }
}

template <class Matrix>
Matrix read_matrix(H5::H5File& file, const std::filesystem::path& path, const std::string& name,
                   const H5::PredType& type) {
  std::vector<std::size_t> dims;
  const auto values = read_values<typename Matrix::Scalar>(file, path, name, 2, type, &dims);
  Matrix m(static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(dims[1]));
  std::copy(values.begin(), values.end(), m.data());
  return m;
}

H5::Group open_or_create_group(H5::H5File& file, const std::string& object) {
  if (object.empty() || object == "/") return file.openGroup("/");
  ensure_groups(file, object, true);
  return file.openGroup(object);
}

}  // namespace

H5Writer::H5Writer(const std::filesystem::path& target, int deflate_level)
    : out_(target), deflate_level_(deflate_level) {
  if (deflate_level < 0 || deflate_level > 9) {
    throw IoError(target.string() + ": deflate level must be 0..9, got " +
                  std::to_string(deflate_level));
  }
  H5::Exception::dontPrint();
  try {
    file_ = std::make_unique<H5::H5File>(out_.temp().string(), H5F_ACC_TRUNC);
  } catch (const H5::Exception& e) {
    rethrow(target, "cannot create HDF5 file", e);
  }
}

H5Writer::~H5Writer() = default;

void H5Writer::write(const std::string& name, const RowMatrixXd& m) {
  write_matrix(*file_, out_.target(), name, m, H5::PredType::NATIVE_DOUBLE, deflate_level_);
}
void H5Writer::write(const std::string& name, const RowMatrixXf& m) {
  write_matrix(*file_, out_.target(), name, m, H5::PredType::NATIVE_FLOAT, deflate_level_);
}
void H5Writer::write(const std::string& name, const RowMatrixXi& m) {
  write_matrix(*file_, out_.target(), name, m, H5::PredType::NATIVE_INT, deflate_level_);
}
void H5Writer::write(const std::string& name, const std::vector<int>& v) {
  write_array(*file_, out_.target(), name, {v.size()}, v.data(), H5::PredType::NATIVE_INT,
              deflate_level_);
}
void H5Writer::write(const std::string& name, const std::vector<float>& v) {
  write_array(*file_, out_.target(), name, {v.size()}, v.data(), H5::PredType::NATIVE_FLOAT,
              deflate_level_);
}
void H5Writer::write(const std::string& name, const std::vector<double>& v) {
  write_array(*file_, out_.target(), name, {v.size()}, v.data(), H5::PredType::NATIVE_DOUBLE,
              deflate_level_);
}
void H5Writer::write(const std::string& name, const std::vector<std::size_t>& dims,
                     const float* data) {
  write_array(*file_, out_.target(), name, std::vector<hsize_t>(dims.begin(), dims.end()), data,
              H5::PredType::NATIVE_FLOAT, deflate_level_);
}

void H5Writer::write_strings(const std::string& name, const std::vector<std::string>& values) {
  try {
    ensure_groups(*file_, name, false);
    // Fixed-length, null-padded, of the longest entry's size: variable-length strings would live
    // in HDF5's global heap, whose reader (H5HG_read, libhdf5 1.10.8) loops forever on a damaged
    // file. HDF5 has no zero-size string type, so the size is at least 1.
    std::size_t width = 1;
    for (const auto& v : values) width = std::max(width, v.size());
    const H5::StrType type = fixed_string_type(width);
    const hsize_t dims[1] = {values.size()};
    H5::DataSpace space(1, dims);
    H5::DSetCreatPropList props;
    if (deflate_level_ > 0 && values.size() * width >= kChunkThreshold * 4) {
      const hsize_t chunk[1] = {std::max<hsize_t>(
          1, std::min<hsize_t>(values.size(), 65536 / static_cast<hsize_t>(width)))};
      props.setChunk(1, chunk);
      props.setDeflate(static_cast<unsigned>(deflate_level_));
    }
    H5::DataSet set = file_->createDataSet(name, type, space, props);
    std::string buffer(values.size() * width, '\0');
    for (std::size_t i = 0; i < values.size(); ++i) {
      std::copy(values[i].begin(), values[i].end(), buffer.begin() + static_cast<long>(i * width));
    }
    if (!values.empty()) set.write(buffer.data(), type);
  } catch (const H5::Exception& e) {
    rethrow(out_.target(), "cannot write dataset '" + name + "'", e);
  }
}

void H5Writer::create_group(const std::string& name) {
  try {
    ensure_groups(*file_, name, true);
  } catch (const H5::Exception& e) {
    rethrow(out_.target(), "cannot create group '" + name + "'", e);
  }
}

void H5Writer::write_attribute(const std::string& name, const std::string& value) {
  write_attribute("/", name, value);
}

void H5Writer::write_attribute(const std::string& object, const std::string& name,
                               const std::string& value) {
  try {
    // Fixed-length of the value's own size (at least 1), never variable-length (write_strings).
    const H5::StrType type = fixed_string_type(std::max<std::size_t>(1, value.size()));
    H5::Group group = open_or_create_group(*file_, object);
    H5::Attribute attr = group.createAttribute(name, type, H5::DataSpace(H5S_SCALAR));
    std::string buffer = value;
    buffer.resize(std::max<std::size_t>(1, value.size()), '\0');
    attr.write(type, buffer.data());
  } catch (const H5::Exception& e) {
    rethrow(out_.target(), "cannot write attribute '" + name + "' of '" + object + "'", e);
  }
}

void H5Writer::write_attribute(const std::string& object, const std::string& name,
                               std::int64_t value) {
  try {
    H5::Group group = open_or_create_group(*file_, object);
    H5::Attribute attr =
        group.createAttribute(name, H5::PredType::STD_I64LE, H5::DataSpace(H5S_SCALAR));
    attr.write(H5::PredType::NATIVE_INT64, &value);
  } catch (const H5::Exception& e) {
    rethrow(out_.target(), "cannot write attribute '" + name + "' of '" + object + "'", e);
  }
}

void H5Writer::write_attribute(const std::string& object, const std::string& name, double value) {
  try {
    H5::Group group = open_or_create_group(*file_, object);
    H5::Attribute attr =
        group.createAttribute(name, H5::PredType::IEEE_F64LE, H5::DataSpace(H5S_SCALAR));
    attr.write(H5::PredType::NATIVE_DOUBLE, &value);
  } catch (const H5::Exception& e) {
    rethrow(out_.target(), "cannot write attribute '" + name + "' of '" + object + "'", e);
  }
}

void H5Writer::commit() {
  try {
    file_->close();
  } catch (const H5::Exception& e) {
    rethrow(out_.target(), "cannot close HDF5 file", e);
  }
  out_.commit();
}

H5Reader::H5Reader(const std::filesystem::path& file, std::string older_writer_advice)
    : path_(file), older_writer_advice_(std::move(older_writer_advice)) {
  H5::Exception::dontPrint();
  if (!std::filesystem::exists(file)) throw IoError(file.string() + ": file does not exist");
  bool is_hdf5 = false;
  try {
    is_hdf5 = H5::H5File::isHdf5(file.string());
  } catch (const H5::Exception& e) {
    rethrow(file, "cannot read file", e);
  }
  if (!is_hdf5) throw IoError(file.string() + ": not an HDF5 file (no HDF5 signature)");
  try {
    file_ = std::make_unique<H5::H5File>(file.string(), H5F_ACC_RDONLY);
  } catch (const H5::Exception& e) {
    rethrow(file, "not a readable HDF5 file", e);
  }
}

H5Reader::~H5Reader() = default;

bool H5Reader::has(const std::string& name) const {
  try {
    return link_exists(*file_, name);
  } catch (const H5::Exception& e) {
    rethrow(path_, "cannot look up '" + name + "'", e);
  }
}

std::vector<std::size_t> H5Reader::shape(const std::string& name) const {
  if (!has(name)) throw IoError(path_.string() + ": no dataset '" + name + "'");
  try {
    std::vector<hsize_t> dims;
    open_dataset(*file_, path_, name, dims);
    return {dims.begin(), dims.end()};
  } catch (const H5::Exception& e) {
    rethrow(path_, "cannot open dataset '" + name + "'", e);
  }
}

std::vector<std::string> H5Reader::children(const std::string& name) const {
  if (!has(name)) throw IoError(path_.string() + ": no group '" + name + "'");
  try {
    H5::Group group = file_->openGroup(name);
    std::vector<std::string> out;
    for (hsize_t i = 0; i < group.getNumObjs(); ++i) out.push_back(group.getObjnameByIdx(i));
    return out;
  } catch (const H5::Exception& e) {
    rethrow(path_, "cannot list group '" + name + "'", e);
  }
}

RowMatrixXd H5Reader::read_double(const std::string& name) const {
  return read_matrix<RowMatrixXd>(*file_, path_, name, H5::PredType::NATIVE_DOUBLE);
}
RowMatrixXf H5Reader::read_float(const std::string& name) const {
  return read_matrix<RowMatrixXf>(*file_, path_, name, H5::PredType::NATIVE_FLOAT);
}
RowMatrixXi H5Reader::read_int(const std::string& name) const {
  return read_matrix<RowMatrixXi>(*file_, path_, name, H5::PredType::NATIVE_INT);
}
std::vector<int> H5Reader::read_ints(const std::string& name) const {
  return read_values<int>(*file_, path_, name, 1, H5::PredType::NATIVE_INT);
}
std::vector<float> H5Reader::read_floats(const std::string& name) const {
  return read_values<float>(*file_, path_, name, 1, H5::PredType::NATIVE_FLOAT);
}
std::vector<double> H5Reader::read_doubles(const std::string& name) const {
  return read_values<double>(*file_, path_, name, 1, H5::PredType::NATIVE_DOUBLE);
}
std::vector<float> H5Reader::read_float_array(const std::string& name,
                                              std::vector<std::size_t>& dims) const {
  return read_values<float>(*file_, path_, name, -1, H5::PredType::NATIVE_FLOAT, &dims);
}

std::vector<std::string> H5Reader::read_strings(const std::string& name) const {
  if (!has(name)) throw IoError(path_.string() + ": no dataset '" + name + "'");
  try {
    std::vector<hsize_t> dims;
    H5::DataSet set = open_dataset(*file_, path_, name, dims);
    if (dims.size() != 1) {
      throw IoError(path_.string() + ": dataset '" + name + "' is not a 1-D list of strings");
    }
    if (set.getTypeClass() != H5T_STRING) {
      throw IoError(path_.string() + ": dataset '" + name + "' is not a list of strings");
    }
    // Only the datatype is looked at: a variable-length string's data (in the global heap) is
    // never read.
    const H5::StrType stored = set.getStrType();
    if (stored.isVariableStr()) variable_length("dataset '" + name + "'");
    const std::size_t width = stored.getSize();
    checked_bytes(path_, "dataset '" + name + "'", dims, width);
    std::vector<std::string> out;
    if (dims[0] == 0) return out;
    H5::StrType type(H5::PredType::C_S1, width);
    type.setCset(stored.getCset());
    type.setStrpad(H5T_STR_NULLPAD);
    std::string buffer(static_cast<std::size_t>(dims[0]) * width, '\0');
    set.read(buffer.data(), type);
    out.reserve(static_cast<std::size_t>(dims[0]));
    for (std::size_t i = 0; i < static_cast<std::size_t>(dims[0]); ++i) {
      const std::string entry = buffer.substr(i * width, width);
      out.push_back(entry.substr(0, entry.find('\0')));
    }
    return out;
  } catch (const H5::Exception& e) {
    rethrow(path_, "cannot read dataset '" + name + "'", e);
  }
}

void H5Reader::variable_length(const std::string& what) const {
  throw IoError(path_.string() + ": " + what + " holds variable-length strings, which skinlab " +
                "no longer reads (libhdf5 can hang on a damaged global heap): " +
                (older_writer_advice_.empty()
                     ? std::string("written by an older skinlab or another program; write it "
                                   "again with this build")
                     : older_writer_advice_));
}

std::string H5Reader::read_attribute(const std::string& name) const {
  return read_attribute("/", name);
}

bool H5Reader::has_attribute(const std::string& object, const std::string& name) const {
  try {
    if (object != "/" && !has(object)) return false;
    return file_->openGroup(object).attrExists(name);
  } catch (const H5::Exception& e) {
    rethrow(path_, "cannot look up attribute '" + name + "' of '" + object + "'", e);
  }
}

namespace {
[[noreturn]] void missing_attribute(const std::filesystem::path& path, const std::string& object,
                                    const std::string& name) {
  throw IoError(path.string() + ": no attribute '" + name + "'" +
                (object == "/" ? std::string() : " on '" + object + "'"));
}
}  // namespace

std::string H5Reader::read_attribute(const std::string& object, const std::string& name) const {
  if (!has_attribute(object, name)) missing_attribute(path_, object, name);
  try {
    H5::Attribute attr = file_->openGroup(object).openAttribute(name);
    if (attr.getTypeClass() != H5T_STRING) {
      throw IoError(path_.string() + ": attribute '" + name + "' of '" + object +
                    "' is not a string");
    }
    const H5::StrType stored = attr.getStrType();
    if (attr.getSpace().getSimpleExtentNpoints() != 1) {
      throw IoError(path_.string() + ": attribute '" + name + "' of '" + object +
                    "' is not a single string");
    }
    if (stored.isVariableStr()) variable_length("attribute '" + name + "' of '" + object + "'");
    const std::size_t width = stored.getSize();
    checked_bytes(path_, "attribute '" + name + "' of '" + object + "'", {1}, width);
    H5::StrType type(H5::PredType::C_S1, width);
    type.setCset(stored.getCset());
    type.setStrpad(H5T_STR_NULLPAD);
    std::string buffer(width, '\0');
    if (!buffer.empty() && H5Aread(attr.getId(), type.getId(), buffer.data()) < 0) {
      throw IoError(path_.string() + ": attribute '" + name + "' of '" + object +
                    "' cannot be read");
    }
    return buffer.substr(0, buffer.find('\0'));
  } catch (const H5::Exception& e) {
    rethrow(path_, "cannot read attribute '" + name + "' of '" + object + "'", e);
  }
}

std::int64_t H5Reader::read_int_attribute(const std::string& object,
                                          const std::string& name) const {
  if (!has_attribute(object, name)) missing_attribute(path_, object, name);
  try {
    H5::Attribute attr = file_->openGroup(object).openAttribute(name);
    if (attr.getTypeClass() != H5T_INTEGER) {
      throw IoError(path_.string() + ": attribute '" + name + "' of '" + object +
                    "' is not an integer");
    }
    if (attr.getSpace().getSimpleExtentNpoints() != 1) {  // read() would write past `value`
      throw IoError(path_.string() + ": attribute '" + name + "' of '" + object +
                    "' is not a single value");
    }
    std::int64_t value = 0;
    attr.read(H5::PredType::NATIVE_INT64, &value);
    return value;
  } catch (const H5::Exception& e) {
    rethrow(path_, "cannot read attribute '" + name + "' of '" + object + "'", e);
  }
}

double H5Reader::read_double_attribute(const std::string& object, const std::string& name) const {
  if (!has_attribute(object, name)) missing_attribute(path_, object, name);
  try {
    H5::Attribute attr = file_->openGroup(object).openAttribute(name);
    if (attr.getTypeClass() != H5T_FLOAT && attr.getTypeClass() != H5T_INTEGER) {
      throw IoError(path_.string() + ": attribute '" + name + "' of '" + object +
                    "' is not a number");
    }
    if (attr.getSpace().getSimpleExtentNpoints() != 1) {  // read() would write past `value`
      throw IoError(path_.string() + ": attribute '" + name + "' of '" + object +
                    "' is not a single value");
    }
    double value = 0;
    attr.read(H5::PredType::NATIVE_DOUBLE, &value);
    return value;
  } catch (const H5::Exception& e) {
    rethrow(path_, "cannot read attribute '" + name + "' of '" + object + "'", e);
  }
}

}  // namespace skinlab::data

#include "framework/data/h5.hpp"

#include <H5Cpp.h>

#include "framework/core/error.hpp"

namespace skinlab::data {

namespace {

[[noreturn]] void rethrow(const std::filesystem::path& file, const std::string& what,
                          const H5::Exception& e) {
  throw IoError(file.string() + ": " + what + ": " + e.getDetailMsg());
}

void ensure_groups(H5::H5File& file, const std::string& name) {
  for (auto pos = name.find('/', 1); pos != std::string::npos; pos = name.find('/', pos + 1)) {
    const std::string group = name.substr(0, pos);
    if (!file.nameExists(group)) file.createGroup(group);
  }
}

template <class Matrix>
void write_matrix(H5::H5File& file, const std::filesystem::path& path, const std::string& name,
                  const Matrix& m, const H5::PredType& type) {
  try {
    ensure_groups(file, name);
    const hsize_t dims[2] = {static_cast<hsize_t>(m.rows()), static_cast<hsize_t>(m.cols())};
    H5::DataSpace space(2, dims);
    H5::DataSet set = file.createDataSet(name, type, space);
    if (m.size() > 0) set.write(m.data(), type);
  } catch (const H5::Exception& e) {
    rethrow(path, "cannot write dataset '" + name + "'", e);
  }
}

template <class Matrix>
Matrix read_matrix(H5::H5File& file, const std::filesystem::path& path, const std::string& name,
                   const H5::PredType& type) {
  if (!file.nameExists(name)) throw IoError(path.string() + ": no dataset '" + name + "'");
  try {
    H5::DataSet set = file.openDataSet(name);
    H5::DataSpace space = set.getSpace();
    if (space.getSimpleExtentNdims() != 2) {
      throw IoError(path.string() + ": dataset '" + name + "' is not 2-D");
    }
    hsize_t dims[2];
    space.getSimpleExtentDims(dims);
    Matrix m(static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(dims[1]));
    if (m.size() > 0) set.read(m.data(), type);  // converts from the stored type
    return m;
  } catch (const H5::Exception& e) {
    rethrow(path, "cannot read dataset '" + name + "'", e);
  }
}

}  // namespace

H5Writer::H5Writer(const std::filesystem::path& target) : out_(target) {
  H5::Exception::dontPrint();
  try {
    file_ = std::make_unique<H5::H5File>(out_.temp().string(), H5F_ACC_TRUNC);
  } catch (const H5::Exception& e) {
    rethrow(target, "cannot create HDF5 file", e);
  }
}

H5Writer::~H5Writer() = default;

void H5Writer::write(const std::string& name, const RowMatrixXd& m) {
  write_matrix(*file_, out_.target(), name, m, H5::PredType::NATIVE_DOUBLE);
}
void H5Writer::write(const std::string& name, const RowMatrixXf& m) {
  write_matrix(*file_, out_.target(), name, m, H5::PredType::NATIVE_FLOAT);
}
void H5Writer::write(const std::string& name, const RowMatrixXi& m) {
  write_matrix(*file_, out_.target(), name, m, H5::PredType::NATIVE_INT);
}

void H5Writer::write_attribute(const std::string& name, const std::string& value) {
  try {
    H5::StrType type(H5::PredType::C_S1, value.size() == 0 ? 1 : value.size());
    H5::Group root = file_->openGroup("/");
    H5::Attribute attr = root.createAttribute(name, type, H5::DataSpace(H5S_SCALAR));
    attr.write(type, value);
  } catch (const H5::Exception& e) {
    rethrow(out_.target(), "cannot write attribute '" + name + "'", e);
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

H5Reader::H5Reader(const std::filesystem::path& file) : path_(file) {
  H5::Exception::dontPrint();
  if (!std::filesystem::exists(file)) throw IoError(file.string() + ": file does not exist");
  try {
    file_ = std::make_unique<H5::H5File>(file.string(), H5F_ACC_RDONLY);
  } catch (const H5::Exception& e) {
    rethrow(file, "not a readable HDF5 file", e);
  }
}

H5Reader::~H5Reader() = default;

bool H5Reader::has(const std::string& name) const { return file_->nameExists(name); }

RowMatrixXd H5Reader::read_double(const std::string& name) const {
  return read_matrix<RowMatrixXd>(*file_, path_, name, H5::PredType::NATIVE_DOUBLE);
}
RowMatrixXf H5Reader::read_float(const std::string& name) const {
  return read_matrix<RowMatrixXf>(*file_, path_, name, H5::PredType::NATIVE_FLOAT);
}
RowMatrixXi H5Reader::read_int(const std::string& name) const {
  return read_matrix<RowMatrixXi>(*file_, path_, name, H5::PredType::NATIVE_INT);
}

std::string H5Reader::read_attribute(const std::string& name) const {
  try {
    H5::Group root = file_->openGroup("/");
    if (!root.attrExists(name)) throw IoError(path_.string() + ": no attribute '" + name + "'");
    H5::Attribute attr = root.openAttribute(name);
    std::string value;
    attr.read(attr.getStrType(), value);
    return value;
  } catch (const H5::Exception& e) {
    rethrow(path_, "cannot read attribute '" + name + "'", e);
  }
}

}  // namespace skinlab::data

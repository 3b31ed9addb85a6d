#include "framework/infer/parameters.hpp"

#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <numeric>

#include "framework/core/error.hpp"
#include "framework/data/h5.hpp"

namespace skinlab::infer {

namespace fs = std::filesystem;

namespace {

constexpr const char* kGroup = "parameters";

std::size_t element_count(const std::vector<std::size_t>& shape) {
  return std::accumulate(shape.begin(), shape.end(), std::size_t{1}, std::multiplies<>());
}

}  // namespace

void write_parameter_file(const fs::path& file, const ParameterFile& p) {
  for (const auto& [name, array] : p.parameters) {  // every check before the file is started
    if (name.empty() || name.find('/') != std::string::npos) {
      throw Error(fmt::format("{}: parameter name '{}' is empty or holds '/'", file.string(), name));
    }
    if (element_count(array.shape) != array.values.size()) {
      throw Error(fmt::format("{}: parameter '{}' has {} values for its shape of {}",
                              file.string(), name, array.values.size(),
                              element_count(array.shape)));
    }
  }
  // Uncompressed: `skinlab-predict` reads the whole file at every start.
  data::H5Writer w(file, /*deflate_level=*/0);
  w.write_attribute("/", "format", std::string(kParameterFormat));
  w.write_attribute("/", "format_version", std::int64_t{kParameterFormatVersion});
  w.write_attribute("/", "model", p.model);
  w.write_attribute("/", "distance", p.distance);
  w.write_attribute("/", "source", p.source);
  w.write_attribute("/", "architecture", p.architecture.dump());
  w.create_group(kGroup);
  for (const auto& [name, array] : p.parameters) {
    w.write(std::string(kGroup) + "/" + name, array.shape, array.values.data());
  }
  w.commit();
}

ParameterFile read_parameter_file(const fs::path& file) {
  if (!fs::exists(file)) throw IoError(file.string() + ": no such parameter file");
  // Version 1 stored its string attributes variable-length (in HDF5's global heap, which this
  // build never reads): its format_version, an integer, is checked before any string.
  const std::string older =
      "written by an older skinlab (parameters format_version 1): re-run `skinlab "
      "export-parameters` on its model with this build";
  const data::H5Reader r(file, older);
  if (r.has_attribute("/", "format_version")) {
    const std::int64_t version = r.read_int_attribute("/", "format_version");
    if (version >= 1 && version < kParameterFormatVersion) {
      throw IoError(fmt::format("{}: written by an older skinlab (parameters format_version {}; "
                                "this build reads version {}): re-run `skinlab "
                                "export-parameters` on its model with this build",
                                file.string(), version, kParameterFormatVersion));
    }
  }
  const auto attribute = [&](const char* name) {
    if (!r.has_attribute("/", name)) {
      throw IoError(fmt::format("{}: no attribute '{}' (not a parameter file of skinlab bundle "
                                "or export-parameters, docs/parameters.md)",
                                file.string(), name));
    }
    return r.read_attribute("/", name);
  };
  const std::string format = attribute("format");
  if (format != kParameterFormat) {
    throw IoError(fmt::format("{}: format '{}', expected '{}'", file.string(), format,
                              kParameterFormat));
  }
  if (!r.has_attribute("/", "format_version")) {
    throw IoError(file.string() + ": no attribute 'format_version'");
  }
  const std::int64_t version = r.read_int_attribute("/", "format_version");
  if (version != kParameterFormatVersion) {
    throw IoError(fmt::format("{}: format_version {}; this build reads version {}", file.string(),
                              version, kParameterFormatVersion));
  }
  ParameterFile p;
  p.model = attribute("model");
  p.distance = attribute("distance");
  p.source = attribute("source");
  const std::string architecture = attribute("architecture");
  try {
    p.architecture = nlohmann::json::parse(architecture);
  } catch (const nlohmann::json::exception& e) {
    throw IoError(fmt::format("{}: attribute 'architecture' is not JSON: {}", file.string(),
                              e.what()));
  }
  if (!p.architecture.is_object()) {
    throw IoError(file.string() + ": attribute 'architecture' is not a JSON object");
  }
  if (!r.has(kGroup)) throw IoError(file.string() + ": no group '/parameters'");
  for (const std::string& name : r.children(kGroup)) {
    ParameterArray array;
    array.values = r.read_float_array(std::string(kGroup) + "/" + name, array.shape);
    for (std::size_t i = 0; i < array.values.size(); ++i) {
      if (!std::isfinite(array.values[i])) {
        throw IoError(fmt::format("{}: parameter '{}' holds {} at element {}", file.string(), name,
                                  array.values[i], i));
      }
    }
    p.parameters.emplace(name, std::move(array));
  }
  return p;
}

}  // namespace skinlab::infer

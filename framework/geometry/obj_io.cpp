#include "framework/geometry/obj_io.hpp"

#include <fmt/format.h>

#include <charconv>
#include <sstream>
#include <string>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/geometry/text_parsing.hpp"

namespace skinlab::geometry {

namespace {

/// Parses the vertex part of an `f` entry ("12", "12/3", "12//4", "-1/2/3") into a 0-based index.
int face_index(std::string_view entry, int num_vertices, const LineContext& at) {
  const std::string_view first = entry.substr(0, entry.find('/'));
  long value = 0;
  if (!parse_number(first, value) || value == 0) at.fail("bad face vertex '" + std::string(entry) + "'");
  const long index = value > 0 ? value - 1 : num_vertices + value;
  if (index < 0 || index >= num_vertices) {
    at.fail("face vertex " + std::to_string(value) + " is out of range (" +
            std::to_string(num_vertices) + " vertices so far)");
  }
  return static_cast<int>(index);
}

}  // namespace

Mesh read_obj(const std::filesystem::path& file) {
  const std::string text = read_file(file);
  std::vector<double> coords;
  std::vector<int> faces;
  for_each_line(text, file, [&](const std::vector<std::string_view>& words, const LineContext& at) {
    if (words[0] == "v") {
      if (words.size() < 4) at.fail("vertex needs 3 coordinates");
      for (int k = 1; k <= 3; ++k) coords.push_back(at.number<double>(words[k], "coordinate"));
    } else if (words[0] == "f") {
      if (words.size() < 4) at.fail("face needs at least 3 vertices");
      const int n = static_cast<int>(coords.size() / 3);
      const int first = face_index(words[1], n, at);
      for (std::size_t k = 2; k + 1 < words.size(); ++k) {
        faces.insert(faces.end(), {first, face_index(words[k], n, at), face_index(words[k + 1], n, at)});
      }
    }
  });
  Mesh mesh;
  mesh.V = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      coords.data(), static_cast<Eigen::Index>(coords.size() / 3), 3);
  mesh.F = Eigen::Map<Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      faces.data(), static_cast<Eigen::Index>(faces.size() / 3), 3);
  mesh.validate(file.string());
  return mesh;
}

void write_obj(const std::filesystem::path& file, const Mesh& mesh) {
  std::string out;
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v) {
    out += fmt::format("v {} {} {}\n", mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2));
  }
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    out += fmt::format("f {} {} {}\n", mesh.F(f, 0) + 1, mesh.F(f, 1) + 1, mesh.F(f, 2) + 1);
  }
  write_file_atomic(file, out);
}

}  // namespace skinlab::geometry

#include "framework/geometry/mesh_parts.hpp"

#include <numeric>

namespace skinlab::geometry {

namespace {

template <typename Faces>
std::vector<int> parts_joined_by(const Mesh& mesh, const Faces& for_each_face) {
  std::vector<int> parent(static_cast<std::size_t>(mesh.num_vertices()));
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for_each_face([&](int f) {
    for (int k = 1; k < 3; ++k) parent[find(mesh.F(f, k))] = find(mesh.F(f, 0));
  });
  for (int v = 0; v < mesh.num_vertices(); ++v) parent[v] = find(v);
  return parent;
}

}  // namespace

std::vector<int> vertex_parts(const Mesh& mesh) {
  return parts_joined_by(mesh, [&](const auto& join) {
    for (int f = 0; f < mesh.num_faces(); ++f) join(f);
  });
}

std::vector<int> vertex_parts(const Mesh& mesh, const std::vector<int>& faces) {
  return parts_joined_by(mesh, [&](const auto& join) {
    for (int f : faces) join(f);
  });
}

}  // namespace skinlab::geometry

#include "framework/geometry/orient_outward.hpp"

#include <Eigen/Geometry>
#include <numeric>
#include <vector>

namespace skinlab::geometry {

Mesh orient_outward(const Mesh& mesh, OrientReport* report) {
  const int nv = mesh.num_vertices(), nf = mesh.num_faces();
  std::vector<int> parent(nv);
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (int f = 0; f < nf; ++f) {
    for (int k = 1; k < 3; ++k) parent[find(mesh.F(f, k))] = find(mesh.F(f, 0));
  }
  // Centroid of the vertices of each part (vertices referenced by no face are their own part).
  std::vector<Eigen::Vector3d> centre(nv, Eigen::Vector3d::Zero());
  std::vector<int> count(nv, 0);
  for (int v = 0; v < nv; ++v) {
    centre[find(v)] += mesh.V.row(v).transpose();
    ++count[find(v)];
  }
  std::vector<double> volume(nv, 0.0);
  std::vector<char> has_face(nv, 0);
  for (int f = 0; f < nf; ++f) {
    const int r = find(mesh.F(f, 0));
    const Eigen::Vector3d c = centre[r] / count[r];
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose() - c;
    const Eigen::Vector3d b = mesh.V.row(mesh.F(f, 1)).transpose() - c;
    const Eigen::Vector3d d = mesh.V.row(mesh.F(f, 2)).transpose() - c;
    volume[r] += a.dot(b.cross(d)) / 6;
    has_face[r] = 1;
  }
  Mesh out = mesh;
  OrientReport local;
  OrientReport& rep = report ? *report : local;
  rep = {};
  for (int v = 0; v < nv; ++v) {
    if (find(v) != v || !has_face[v]) continue;
    ++rep.parts;
    if (volume[v] < 0) ++rep.flipped_parts;
  }
  for (int f = 0; f < nf; ++f) {
    if (volume[find(mesh.F(f, 0))] < 0) std::swap(out.F(f, 1), out.F(f, 2));
  }
  return out;
}

}  // namespace skinlab::geometry

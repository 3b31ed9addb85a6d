#include "framework/geometry/orient_outward.hpp"

#include "framework/geometry/mesh_parts.hpp"

#include <Eigen/Geometry>
#include <vector>

namespace skinlab::geometry {

Mesh orient_outward(const Mesh& mesh, OrientReport* report) {
  const int nv = mesh.num_vertices(), nf = mesh.num_faces();
  const std::vector<int> part = vertex_parts(mesh);
  // Centroid of the vertices of each part (vertices referenced by no face are their own part).
  std::vector<Eigen::Vector3d> centre(nv, Eigen::Vector3d::Zero());
  std::vector<int> count(nv, 0);
  for (int v = 0; v < nv; ++v) {
    centre[part[v]] += mesh.V.row(v).transpose();
    ++count[part[v]];
  }
  std::vector<double> volume(nv, 0.0);
  std::vector<char> has_face(nv, 0);
  for (int f = 0; f < nf; ++f) {
    const int r = part[mesh.F(f, 0)];
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
    if (part[v] != v || !has_face[v]) continue;
    ++rep.parts;
    if (volume[v] < 0) ++rep.flipped_parts;
  }
  for (int f = 0; f < nf; ++f) {
    if (volume[part[mesh.F(f, 0)]] < 0) std::swap(out.F(f, 1), out.F(f, 2));
  }
  return out;
}

}  // namespace skinlab::geometry

#include "framework/geometry/one_ring.hpp"

#include <algorithm>

namespace skinlab::geometry {

OneRing one_ring(const Mesh& mesh) {
  mesh.validate("one_ring");
  OneRing out;
  out.neighbours.resize(static_cast<size_t>(mesh.num_vertices()));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      if (a == b) continue;
      out.neighbours[static_cast<size_t>(a)].push_back(b);
      out.neighbours[static_cast<size_t>(b)].push_back(a);
    }
  }
  Eigen::Index total = 0;
  for (auto& list : out.neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    total += static_cast<Eigen::Index>(list.size());
  }
  out.edges.resize(2, total);
  Eigen::Index e = 0;
  for (size_t i = 0; i < out.neighbours.size(); ++i) {
    for (int j : out.neighbours[i]) {
      out.edges(0, e) = static_cast<int>(i);
      out.edges(1, e) = j;
      ++e;
    }
  }
  return out;
}

}  // namespace skinlab::geometry

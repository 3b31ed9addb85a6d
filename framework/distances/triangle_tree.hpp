#pragma once
/// \file
/// CGAL's AABB tree over a mesh's triangles, for the ray and segment queries of the distances
/// (volumetric_geodesic's visibility, leaf_bones' ray to the surface). Zero-area faces are left
/// out: they block no ray, and CGAL's segment–triangle test requires a proper triangle.

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <vector>

#include "framework/geometry/mesh.hpp"

namespace skinlab::distances::aabb {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Segment = Kernel::Segment_3;
using Ray = Kernel::Ray_3;
using Triangle = Kernel::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

/// The non-degenerate triangles of a mesh and the tree over them, built at construction (so
/// concurrent queries never trigger CGAL's lazy build). The tree refers to the triangles, so the
/// object is neither copied nor moved.
class TriangleTree {
 public:
  explicit TriangleTree(const geometry::Mesh& mesh) {
    triangles_.reserve(static_cast<std::size_t>(mesh.num_faces()));
    faces_.reserve(static_cast<std::size_t>(mesh.num_faces()));
    const auto point = [&](int v) { return Point(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)); };
    for (int f = 0; f < mesh.num_faces(); ++f) {
      Triangle t(point(mesh.F(f, 0)), point(mesh.F(f, 1)), point(mesh.F(f, 2)));
      if (t.is_degenerate()) continue;
      triangles_.push_back(t);
      faces_.push_back(f);
    }
    tree_.insert(triangles_.cbegin(), triangles_.cend());
    tree_.build();
  }
  TriangleTree(const TriangleTree&) = delete;
  TriangleTree& operator=(const TriangleTree&) = delete;

  const Tree& tree() const { return tree_; }
  /// The mesh face (row of Mesh::F) of a primitive a query returned.
  int face(TriangleIterator primitive) const {
    return faces_[static_cast<std::size_t>(primitive - triangles_.cbegin())];
  }

 private:
  std::vector<Triangle> triangles_;
  std::vector<int> faces_;  // mesh face of each triangle
  Tree tree_;
};

}  // namespace skinlab::distances::aabb

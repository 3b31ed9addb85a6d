#include "framework/distances/leaf_bones.hpp"

#include "framework/distances/triangle_tree.hpp"
#include "framework/geometry/mesh_parts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <utility>
#include <vector>

namespace skinlab::distances {

namespace {
// Nested so that these names never meet another file's in a unity translation unit.
namespace leaf_geometry {

using aabb::Kernel;
using aabb::Point;
using aabb::Ray;
using aabb::Tree;

Point point(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }
Eigen::Vector3d vec(const Point& p) { return {p.x(), p.y(), p.z()}; }

/// Below this length (in mesh units, relative to the mesh's size) a direction is undefined.
constexpr double kCoincident = 1e-9;

LeafBoneOptions::Kind parse_kind(const config::Node& node) {
  const auto name = node.as<std::string>();
  if (name == "helper") return LeafBoneOptions::Kind::kHelper;
  if (name == "extended") return LeafBoneOptions::Kind::kExtended;
  node.fail("expected 'helper' (the paper's zero-length bone) or 'extended', got '" + name + "'");
}

/// Where the ray from a leaf ends, from its crossings (distance along the ray, mesh part):
/// `first_surface` the nearest; `enclosing_parts` the largest nearest crossing over the parts
/// crossed an odd number of times, or the nearest when there is none (leaf_bones.hpp). A ray
/// through an edge or a vertex meets every triangle there at the same distance: crossings of one
/// part closer than `coincident` count once.
double ray_end(std::vector<std::pair<double, int>> crossings, LeafBoneOptions::End ends_at,
               double coincident) {
  std::sort(crossings.begin(), crossings.end());
  const double first = crossings.front().first;
  if (ends_at == LeafBoneOptions::End::kFirstSurface) return first;
  struct Crossed {
    int count = 0;        // distinct crossings
    double nearest = 0;   // the part's first crossing
    double last = 0;      // the latest one counted
  };
  std::map<int, Crossed> parts;
  for (const auto& [t, part] : crossings) {  // in order of distance
    Crossed& c = parts[part];
    if (c.count == 0) c.nearest = t;
    if (c.count == 0 || t - c.last > coincident) ++c.count;
    c.last = t;
  }
  double end = -1;
  for (const auto& [p, c] : parts) {
    if (c.count % 2 == 1) end = std::max(end, c.nearest);
  }
  return end >= 0 ? end : first;
}

/// The `extended` construction (leaf_bones.hpp) on a validated mesh and skeleton.
Eigen::MatrixXd tips_by_rays(const geometry::Mesh& mesh, const geometry::Skeleton& skeleton,
                             double max_length, double coincident, LeafBoneOptions::End ends_at,
                             bool roots) {
  const aabb::TriangleTree triangles(mesh);
  const Tree& tree = triangles.tree();
  const std::vector<int> part = ends_at == LeafBoneOptions::End::kEnclosingParts
                                    ? geometry::vertex_parts(mesh)
                                    : std::vector<int>{};  // unused by first_surface

  // The end of the bone from `leaf` along `along` (the bone before it, whose length bounds it),
  // or `leaf` itself when the ray meets nothing ahead.
  const auto tip_along = [&](const Eigen::Vector3d& leaf,
                             const Eigen::Vector3d& along) -> Eigen::Vector3d {
    const double parent_length = along.norm();
    const Eigen::Vector3d d = along / parent_length;
    std::vector<Tree::Intersection_and_primitive_id<Ray>::Type> hits;
    tree.all_intersections(Ray(point(leaf), point(leaf + d)), std::back_inserter(hits));
    std::vector<std::pair<double, int>> crossings;  // (distance along the ray, mesh part)
    for (const auto& hit : hits) {
      // A ray meets a triangle in a point, or in a segment when it runs in the triangle's plane
      // (then its nearer end ahead of the joint counts, once).
      double t = std::numeric_limits<double>::infinity();
      if (const Point* p = boost::get<Point>(&hit.first)) {
        const double at = (vec(*p) - leaf).dot(d);
        if (at > coincident) t = at;
      } else if (const Kernel::Segment_3* s = boost::get<Kernel::Segment_3>(&hit.first)) {
        for (const Point& q : {s->source(), s->target()}) {
          const double at = (vec(q) - leaf).dot(d);
          if (at > coincident) t = std::min(t, at);
        }
      }
      if (!std::isfinite(t)) continue;
      crossings.emplace_back(t, part.empty() ? 0 : part[mesh.F(triangles.face(hit.second), 0)]);
    }
    if (crossings.empty()) return leaf;  // nothing ahead: the joint is outside, facing away
    const double end = ray_end(std::move(crossings), ends_at, coincident);
    return leaf + std::min(end, max_length * parent_length) * d;
  };

  Eigen::MatrixXd tips = skeleton.positions;
  const auto children = skeleton.children();
  const auto joint = [&](int j) -> Eigen::Vector3d { return skeleton.positions.row(j).transpose(); };
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    if (!children[j].empty()) continue;
    int a = skeleton.parents[j];
    while (a >= 0 && (joint(j) - joint(a)).norm() <= coincident) a = skeleton.parents[a];
    if (a < 0) continue;  // a one-joint skeleton, or every ancestor at the leaf's position
    tips.row(j) = tip_along(joint(j), joint(j) - joint(a)).transpose();
  }
  // A root with one child ends its chain as a leaf does: the same ray, from the root away from
  // its child (the first descendant on the chain at another position).
  const int r = skeleton.root();
  if (roots && children[r].size() == 1) {
    int c = children[r].front();
    while ((joint(c) - joint(r)).norm() <= coincident && children[c].size() == 1) {
      c = children[c].front();
    }
    if ((joint(c) - joint(r)).norm() > coincident) {
      tips.row(r) = tip_along(joint(r), joint(r) - joint(c)).transpose();
    }
  }
  return tips;
}

}  // namespace leaf_geometry
}  // namespace

LeafBoneOptions LeafBoneOptions::from(const config::Node& node) {
  LeafBoneOptions o;
  if (!node.exists() || node.is_null()) return o;
  if (node.is_scalar()) {
    o.kind = leaf_geometry::parse_kind(node);
    return o;
  }
  config::Fields f(node, "preprocess.leaf_bones");  // `type` is reserved: read below
  if (!node["type"].exists()) node.fail("needs 'type: helper' or 'type: extended'");
  o.kind = leaf_geometry::parse_kind(node["type"]);
  f.optional("max_length", o.max_length);
  f.check(o.max_length > 0, "max_length", "must be positive");
  std::string ends_at = "first_surface";
  f.optional("ends_at", ends_at)
      .check(ends_at == "first_surface" || ends_at == "enclosing_parts", "ends_at",
             "must be 'first_surface' or 'enclosing_parts', got '" + ends_at + "'");
  if (ends_at == "enclosing_parts") o.ends_at = LeafBoneOptions::End::kEnclosingParts;
  f.optional("roots", o.roots)
      .check(!o.roots || o.kind == LeafBoneOptions::Kind::kExtended, "roots",
             "needs 'type: extended' (the paper's helper bones have no extent to give a root)");
  f.finish();
  return o;
}

std::string LeafBoneOptions::name() const {
  return kind == Kind::kExtended ? "extended" : "helper";
}

Eigen::MatrixXd extended_leaf_tips(const geometry::Mesh& mesh, const geometry::Skeleton& skeleton,
                                   double max_length, const std::string& source,
                                   LeafBoneOptions::End ends_at, bool roots) {
  mesh.validate(source);
  skeleton.validate(source);
  if (!(max_length > 0)) {
    throw geometry::GeometryError(source + ": leaf bone max_length must be positive, got " +
                                  std::to_string(max_length));
  }
  const double scale = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  const double coincident = leaf_geometry::kCoincident * std::max(scale, 1.0);

  return leaf_geometry::tips_by_rays(mesh, skeleton, max_length, coincident, ends_at, roots);
}

void place_leaf_bones(const geometry::Mesh& mesh, geometry::Skeleton& skeleton,
                      const LeafBoneOptions& options, const std::string& source) {
  if (options.kind == LeafBoneOptions::Kind::kHelper) {
    skeleton.leaf_tips.resize(0, 0);
    return;
  }
  skeleton.leaf_tips =
      extended_leaf_tips(mesh, skeleton, options.max_length, source, options.ends_at, options.roots);
}

}  // namespace skinlab::distances

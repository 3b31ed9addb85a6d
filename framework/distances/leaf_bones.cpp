#include "framework/distances/leaf_bones.hpp"

#include "framework/distances/triangle_tree.hpp"

#include <cmath>
#include <limits>
#include <optional>
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

/// The `extended` construction (leaf_bones.hpp) on a validated mesh and skeleton.
Eigen::MatrixXd tips_by_rays(const geometry::Mesh& mesh, const geometry::Skeleton& skeleton,
                             double max_length, double coincident) {
  const aabb::TriangleTree triangles(mesh);
  const Tree& tree = triangles.tree();

  Eigen::MatrixXd tips = skeleton.positions;
  const auto children = skeleton.children();
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    if (!children[j].empty()) continue;
    const Eigen::Vector3d leaf = skeleton.positions.row(j).transpose();
    int a = skeleton.parents[j];
    while (a >= 0 && (leaf - skeleton.positions.row(a).transpose()).norm() <= coincident) {
      a = skeleton.parents[a];
    }
    if (a < 0) continue;  // a one-joint skeleton, or every ancestor at the leaf's position
    const Eigen::Vector3d along = leaf - skeleton.positions.row(a).transpose();
    const double parent_length = along.norm();
    const Eigen::Vector3d d = along / parent_length;

    std::vector<Tree::Intersection_and_primitive_id<Ray>::Type> hits;
    tree.all_intersections(Ray(point(leaf), point(leaf + d)), std::back_inserter(hits));
    double first = std::numeric_limits<double>::infinity();
    for (const auto& hit : hits) {
      // A ray meets a triangle in a point, or in a segment when it runs in the triangle's plane
      // (then its nearer end counts).
      if (const Point* p = boost::get<Point>(&hit.first)) {
        const double t = (vec(*p) - leaf).dot(d);
        if (t > coincident) first = std::min(first, t);
      } else if (const Kernel::Segment_3* s = boost::get<Kernel::Segment_3>(&hit.first)) {
        for (const Point& q : {s->source(), s->target()}) {
          const double t = (vec(q) - leaf).dot(d);
          if (t > coincident) first = std::min(first, t);
        }
      }
    }
    if (!std::isfinite(first)) continue;  // nothing ahead: the joint is outside, facing away
    tips.row(j) = (leaf + std::min(first, max_length * parent_length) * d).transpose();
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
  f.finish();
  return o;
}

std::string LeafBoneOptions::name() const {
  return kind == Kind::kExtended ? "extended" : "helper";
}

Eigen::MatrixXd extended_leaf_tips(const geometry::Mesh& mesh, const geometry::Skeleton& skeleton,
                                   double max_length, const std::string& source) {
  mesh.validate(source);
  skeleton.validate(source);
  if (!(max_length > 0)) {
    throw geometry::GeometryError(source + ": leaf bone max_length must be positive, got " +
                                  std::to_string(max_length));
  }
  const double scale = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  const double coincident = leaf_geometry::kCoincident * std::max(scale, 1.0);

  return leaf_geometry::tips_by_rays(mesh, skeleton, max_length, coincident);
}

void place_leaf_bones(const geometry::Mesh& mesh, geometry::Skeleton& skeleton,
                      const LeafBoneOptions& options, const std::string& source) {
  if (options.kind == LeafBoneOptions::Kind::kHelper) {
    skeleton.leaf_tips.resize(0, 0);
    return;
  }
  skeleton.leaf_tips = extended_leaf_tips(mesh, skeleton, options.max_length, source);
}

}  // namespace skinlab::distances

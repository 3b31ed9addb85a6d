#include "baselines/bone_heat/bone_heat.hpp"

#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <unordered_map>
#include <vector>

#include "framework/core/registry.hpp"
#include "framework/distances/triangle_tree.hpp"
#include "framework/geometry/closest_point_on_segment.hpp"
#include "framework/geometry/mesh_parts.hpp"
#include "framework/geometry/orient_outward.hpp"

namespace skinlab::baselines {

namespace {

using geometry::GeometryError;
// The CGAL types of the distances' AABB tree; the tree itself is built here, since the
// triangles kept differ from aabb::TriangleTree's (see the face filter below).
using distances::aabb::Point;
using distances::aabb::Segment;
using distances::aabb::Tree;
using distances::aabb::Triangle;
using distances::aabb::TriangleIterator;

const char* const kBoneHeatOwner = "binder 'bone_heat'";
constexpr double kDistanceEpsilon = 1e-4;  // Blender DISTANCE_EPSILON (relative tie tolerance)
constexpr double kMinDistance = 1e-4;      // Blender: mindist = max(mindist, 1e-4)
constexpr double kRayShrink = 1e-5;        // Blender: ray starts 1e-5 along, ends 1e-5 short
constexpr double kFrontFacing = -1e-5;     // Blender bvh_callback: dot(n, dir) < -1e-5 blocks
constexpr double kDegenerateRatio = 1e-10;  // as geometry::LaplacianOptions::degenerate_ratio

/// Cotangent of the angle at `o` in triangle (o, p, q); needs a non-degenerate triangle.
double cotangent(const Eigen::Vector3d& o, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d u = p - o, v = q - o;
  return u.dot(v) / u.cross(v).norm();
}

bool degenerate(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double longest =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return !((b - a).cross(c - a).norm() > kDegenerateRatio * longest);
}

std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

/// One segment per joint, as Blender builds bones from a joint-only skeleton (its glTF
/// importer's default "Temperance" bone heuristic, which the file comment describes): from the
/// joint to its child when it has one, toward the mean of its children's offsets for the
/// shortest child's length when it has several, and a leaf's helper bone (to its leaf tip when
/// the skeleton has them) when it has none. Children at the joint itself (closer than
/// kCoincident) are not directions; a joint with only such children is a point.
void joint_segments(const geometry::Skeleton& skeleton, std::vector<Eigen::Vector3d>& root,
                    std::vector<Eigen::Vector3d>& tip) {
  constexpr double kCoincident = 1e-6;  // metres in the normalised frame
  const auto children = skeleton.children();
  const int nj = skeleton.num_joints();
  root.assign(nj, Eigen::Vector3d::Zero());
  tip.assign(nj, Eigen::Vector3d::Zero());
  for (int j = 0; j < nj; ++j) {
    root[j] = skeleton.positions.row(j).transpose();
    if (children[j].empty()) {
      tip[j] = skeleton.bone_end(geometry::Bone{j, j, true});
      continue;
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    double shortest = std::numeric_limits<double>::infinity();
    int counted = 0, nearest = -1;
    for (int c : children[j]) {
      const Eigen::Vector3d offset = skeleton.positions.row(c).transpose() - root[j];
      if (offset.norm() <= kCoincident) continue;
      mean += offset;
      ++counted;
      if (offset.norm() < shortest) {
        shortest = offset.norm();
        nearest = c;
      }
    }
    if (counted == 0) {
      tip[j] = root[j];
    } else if (counted == 1 || mean.norm() <= kCoincident) {
      tip[j] = skeleton.positions.row(nearest).transpose();  // children cancelling out: nearest
    } else {
      tip[j] = root[j] + shortest * mean.normalized();
    }
  }
}

/// #V×#J weights of joint_segments' sources as #V×#B bone weights: each joint's weight goes to
/// the bone starting at that joint whose segment is nearest to the vertex (Euclidean), as the
/// preprocessing's bone-level rule splits an artist's joint weight among a joint's bones by
/// distance (data/preprocess.hpp). Every joint starts a bone (its children's or its helper).
Eigen::MatrixXd onto_bones(const Eigen::MatrixXd& W, const geometry::Mesh& mesh,
                           const geometry::Skeleton& skeleton,
                           const std::vector<geometry::Bone>& bones) {
  std::vector<std::vector<int>> starting(skeleton.num_joints());
  for (int b = 0; b < static_cast<int>(bones.size()); ++b) starting[bones[b].start].push_back(b);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(W.rows(), static_cast<Eigen::Index>(bones.size()));
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    const Eigen::Vector3d x = mesh.V.row(v).transpose();
    for (int j = 0; j < skeleton.num_joints(); ++j) {
      if (W(v, j) <= 0) continue;
      int best = starting[j].front();
      double best_distance = std::numeric_limits<double>::infinity();
      for (int b : starting[j]) {
        const double d = geometry::point_segment_distance(
            x, skeleton.positions.row(j).transpose(), skeleton.bone_end(bones[b]));
        if (d < best_distance) {
          best_distance = d;
          best = b;
        }
      }
      out(v, best) += W(v, j);
    }
  }
  return out;
}

}  // namespace

BoneHeat::Options BoneHeat::Options::from(const config::Node& node) {
  Options o;
  config::Fields f(node, kBoneHeatOwner);
  f.optional("heat_constant", o.heat_constant)
      .check(std::isfinite(o.heat_constant) && o.heat_constant > 0, "heat_constant",
             "must be positive");
  f.optional("closest", o.closest)
      .check(o.closest == "visible" || o.closest == "blender", "closest",
             "must be 'visible' or 'blender', got '" + o.closest + "'");
  f.optional("heat_sources", o.heat_sources)
      .check(o.heat_sources == "bones" || o.heat_sources == "joints", "heat_sources",
             "must be 'bones' or 'joints', got '" + o.heat_sources + "'");
  f.optional("normal_weighted_distance", o.normal_weighted_distance);
  f.optional("orient_outward", o.orient_outward);
  f.optional("weight_limit_start", o.weight_limit_start)
      .check(std::isfinite(o.weight_limit_start) && o.weight_limit_start >= 0 &&
                 o.weight_limit_start <= 1,
             "weight_limit_start", "must be in [0, 1]");
  f.optional("weight_limit_end", o.weight_limit_end)
      .check(std::isfinite(o.weight_limit_end) && o.weight_limit_end >= 0 &&
                 (o.weight_limit_end < o.weight_limit_start ||
                  (o.weight_limit_end == 0 && o.weight_limit_start == 0)),
             "weight_limit_end", "must be in [0, weight_limit_start)");
  f.finish();
  return o;
}

Eigen::MatrixXd BoneHeat::bind(const geometry::Mesh& input, const geometry::Skeleton& skeleton,
                               BoneHeatStats* stats) const {
  input.validate(kBoneHeatOwner);
  skeleton.validate(kBoneHeatOwner);
  BoneHeatStats local_stats;
  BoneHeatStats& st = stats ? *stats : local_stats;
  st = {};
  geometry::OrientReport orient;
  const geometry::Mesh mesh =
      options_.orient_outward ? geometry::orient_outward(input, &orient) : input;
  st.flipped_parts = orient.flipped_parts;
  const auto bones = skeleton.bones();
  const int nv = mesh.num_vertices();
  const auto X = [&](int v) -> Eigen::Vector3d { return mesh.V.row(v).transpose(); };
  // The heat sources: one segment per bone, or per joint (`heat_sources: joints`). Below, "bone"
  // b means source b; the sources' weights become bone weights at the end.
  const bool per_joint = options_.heat_sources == "joints";
  std::vector<Eigen::Vector3d> root, tip;
  if (per_joint) {
    joint_segments(skeleton, root, tip);
  } else {
    for (const auto& bone : bones) {
      root.push_back(skeleton.positions.row(bone.start).transpose());
      tip.push_back(skeleton.bone_end(bone));
    }
  }
  const int nb = static_cast<int>(root.size());

  // ---- triangles: normals, AABB tree, the Laplacian, areas, components ----------------------
  std::vector<int> good_faces;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    if (!degenerate(X(mesh.F(f, 0)), X(mesh.F(f, 1)), X(mesh.F(f, 2)))) good_faces.push_back(f);
  }
  std::vector<Triangle> triangles;
  std::vector<Eigen::Vector3d> face_normals;
  std::vector<char> in_face(nv, 0);
  Eigen::MatrixXd normals = Eigen::MatrixXd::Zero(nv, 3);
  const auto point = [&](int v) { return Point(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)); };
  for (int f : good_faces) {
    const int i = mesh.F(f, 0), j = mesh.F(f, 1), k = mesh.F(f, 2);
    triangles.emplace_back(point(i), point(j), point(k));
    const Eigen::Vector3d n = (X(j) - X(i)).cross(X(k) - X(i)).normalized();
    face_normals.push_back(n);
    for (int v : {i, j, k}) {
      normals.row(v) += n.transpose();
      in_face[v] = 1;
    }
  }
  for (int v = 0; v < nv; ++v) {
    const double length = normals.row(v).norm();
    if (length > 0) normals.row(v) /= length;
  }
  Tree tree(triangles.cbegin(), triangles.cend());
  tree.build();

  std::unordered_map<std::uint64_t, int> edge_faces;
  for (int f : good_faces) {
    for (int k = 0; k < 3; ++k) ++edge_faces[edge_key(mesh.F(f, k), mesh.F(f, (k + 1) % 3))];
  }
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::VectorXd area = Eigen::VectorXd::Zero(nv);  // Blender's varea before 0.5 / varea
  for (int f : good_faces) {
    const int id[3] = {mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)};
    const Eigen::Vector3d p[3] = {X(id[0]), X(id[1]), X(id[2])};
    double cot[3];  // cot[k]: angle at corner k, opposite edge (k+1, k+2)
    for (int k = 0; k < 3; ++k) cot[k] = cotangent(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
    int obtuse = -1;
    for (int k = 0; k < 3; ++k) {
      if (cot[k] < 0) obtuse = k;  // angle > 90°
    }
    if (obtuse >= 0) {
      const double a = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
      for (int k = 0; k < 3; ++k) area[id[k]] += k == obtuse ? a : 0.5 * a;
    } else {
      for (int k = 0; k < 3; ++k) {
        // Edges at corner k are (k, k+1), opposite corner k+2, and (k, k+2), opposite k+1.
        const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        area[id[k]] += 0.25 * (cot[k2] * (p[k1] - p[k]).squaredNorm() +
                               cot[k1] * (p[k2] - p[k]).squaredNorm());
      }
    }
    for (int k = 0; k < 3; ++k) {
      const int a = id[(k + 1) % 3], b = id[(k + 2) % 3];
      const double t = cot[k] / edge_faces[edge_key(a, b)];
      triplets.emplace_back(a, b, -t);
      triplets.emplace_back(b, a, -t);
      triplets.emplace_back(a, a, t);
      triplets.emplace_back(b, b, t);
    }
  }

  // Components over non-degenerate triangles.
  const std::vector<int> part = geometry::vertex_parts(mesh, good_faces);

  // ---- distances, visibility, H and p ---------------------------------------------------------
  const auto visible = [&](int v, const Eigen::Vector3d& target) {
    if (!in_face[v]) return true;
    const Eigen::Vector3d x = X(v), dir = target - x;
    const double length = dir.norm();
    if (length < 1e-12) return true;  // the vertex lies on the bone
    const Eigen::Vector3d a = x + kRayShrink * dir, b = x + (1 - kRayShrink) * dir;
    std::vector<TriangleIterator> hits;
    tree.all_intersected_primitives(Segment(Point(a.x(), a.y(), a.z()), Point(b.x(), b.y(), b.z())),
                                    std::back_inserter(hits));
    const Eigen::Vector3d unit = dir / length;
    for (const auto& it : hits) {
      if (face_normals[it - triangles.cbegin()].dot(unit) < kFrontFacing) return false;
    }
    return true;
  };
  const bool blender_rule = options_.closest == "blender";
  Eigen::VectorXd H = Eigen::VectorXd::Zero(nv);
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(nv, nb);  // p_i(j), rows sum to 1 or 0
  tbb::parallel_for(0, nv, [&](int v) {
    const Eigen::Vector3d x = X(v);
    std::vector<std::pair<double, int>> d(nb);
    std::vector<Eigen::Vector3d> closest(nb);
    for (int b = 0; b < nb; ++b) {
      closest[b] = geometry::closest_point_on_segment(x, root[b], tip[b]);
      const Eigen::Vector3d r = x - closest[b];
      double dist = r.norm();
      if (options_.normal_weighted_distance) {
        const double cosine = dist > 0 ? r.dot(normals.row(v).transpose()) / dist : 0.0;
        dist /= 0.5 * (cosine + 1.001);
      }
      d[b] = {dist, b};
    }
    std::sort(d.begin(), d.end());
    double mindist = d[0].first;
    std::vector<int> nearest;
    if (blender_rule) {
      for (const auto& [dist, b] : d) {
        if (dist > mindist * (1 + kDistanceEpsilon)) break;
        if (visible(v, closest[b])) nearest.push_back(b);
      }
    } else {
      std::size_t first = 0;
      while (first < d.size() && !visible(v, closest[d[first].second])) ++first;
      if (first < d.size()) {
        mindist = d[first].first;
        nearest.push_back(d[first].second);
        for (std::size_t k = first + 1; k < d.size(); ++k) {
          if (d[k].first > mindist * (1 + kDistanceEpsilon)) break;
          if (visible(v, closest[d[k].second])) nearest.push_back(d[k].second);
        }
      }
    }
    if (nearest.empty()) return;
    const double k = static_cast<double>(nearest.size());
    const double m = std::max(mindist, kMinDistance);
    H[v] = k * options_.heat_constant / (m * m);
    for (int b : nearest) P(v, b) = 1 / k;
  });

  // ---- which vertices are solved, which fall back --------------------------------------------
  std::vector<char> component_heated(nv, 0);
  for (int v = 0; v < nv; ++v) {
    if (H[v] > 0) component_heated[part[v]] = 1;
    if (H[v] == 0) ++st.invisible_vertices;
  }
  std::vector<int> active_index(nv, -1);
  std::vector<int> active;
  std::vector<char> fallback(nv, 0);
  std::vector<char> counted_component(nv, 0);
  for (int v = 0; v < nv; ++v) {
    const int c = part[v];
    if (area[v] > 0 && component_heated[c]) {
      active_index[v] = static_cast<int>(active.size());
      active.push_back(v);
    } else if (area[v] > 0 || H[v] == 0) {
      // A component without any heat source (area[v] > 0 here means !component_heated), or a
      // zero-area vertex that sees no bone.
      fallback[v] = 1;
      ++st.fallback_vertices;
      if (area[v] > 0 && !counted_component[c]) {
        counted_component[c] = 1;
        ++st.fallback_components;
      }
    }
    // else: a zero-area vertex that sees a bone keeps w = p.
  }

  // ---- one factorisation, #B solves ----------------------------------------------------------
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(nv, nb);
  const int na = static_cast<int>(active.size());
  if (na > 0) {
    std::vector<Eigen::Triplet<double>> reduced;
    reduced.reserve(triplets.size() + na);
    for (const auto& t : triplets) {
      const int r = active_index[t.row()], c = active_index[t.col()];
      if (r >= 0 && c >= 0) reduced.emplace_back(r, c, t.value());
    }
    Eigen::MatrixXd rhs(na, nb);
    for (int r = 0; r < na; ++r) {
      const int v = active[r];
      const double h = 2 * area[v] * H[v];
      reduced.emplace_back(r, r, h);
      rhs.row(r) = h * P.row(v);
    }
    Eigen::SparseMatrix<double> A(na, na);
    A.setFromTriplets(reduced.begin(), reduced.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
    if (solver.info() != Eigen::Success) {
      throw GeometryError(std::string(kBoneHeatOwner) + ": the heat system (" + std::to_string(na) +
                          " vertices) could not be factorised");
    }
    const Eigen::MatrixXd solution = solver.solve(rhs);
    if (solver.info() != Eigen::Success || !solution.allFinite()) {
      throw GeometryError(std::string(kBoneHeatOwner) + ": the heat system (" + std::to_string(na) +
                          " vertices) has no finite solution");
    }
    for (int r = 0; r < na; ++r) W.row(active[r]) = solution.row(r);
  }

  // ---- weight limit, fallbacks, renormalisation ----------------------------------------------
  const double start = options_.weight_limit_start, end = options_.weight_limit_end;
  const auto limit = [&](double w) {
    if (w < end) return 0.0;
    if (w < start) return (w - end) / (start - end) * start;
    return w;
  };
  for (int v = 0; v < nv; ++v) {
    if (fallback[v]) {
      const Eigen::Vector3d x = X(v);
      Eigen::VectorXd d(nb);
      for (int b = 0; b < nb; ++b) d[b] = geometry::point_segment_distance(x, root[b], tip[b]);
      const double m = d.minCoeff();
      for (int b = 0; b < nb; ++b) W(v, b) = d[b] <= m * (1 + kDistanceEpsilon) ? 1.0 : 0.0;
    } else if (active_index[v] < 0) {
      W.row(v) = P.row(v);
    } else {
      Eigen::RowVectorXd row = W.row(v).cwiseMax(0.0);
      Eigen::RowVectorXd limited = row.unaryExpr(limit);
      if (limited.sum() > 0) {
        W.row(v) = limited;
      } else {
        ++st.limited_rows;
        W.row(v) = row;
      }
    }
    const double sum = W.row(v).sum();
    if (!(sum > 0) || !std::isfinite(sum)) {
      throw GeometryError(std::string(kBoneHeatOwner) + ": vertex " + std::to_string(v) +
                          " has no positive bone weight");
    }
    W.row(v) /= sum;
  }
  return per_joint ? onto_bones(W, mesh, skeleton, bones) : W;
}

}  // namespace skinlab::baselines

SKINLAB_REGISTER(binder, bone_heat, skinlab::baselines::BoneHeat);

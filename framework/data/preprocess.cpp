#include "framework/data/preprocess.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>
#include <numeric>
#include <optional>
#include <set>

#include "framework/binders/binder.hpp"
#include "framework/core/error.hpp"
#include "framework/core/registry.hpp"
#include "framework/geometry/average_vertex_data.hpp"
#include "framework/geometry/geodesic_neighbours.hpp"
#include "framework/geometry/laplacian.hpp"
#include "framework/geometry/merge_vertices.hpp"
#include "framework/geometry/normalize.hpp"
#include "framework/geometry/one_ring.hpp"
#include "framework/geometry/subdivide.hpp"
#include "framework/geometry/weightless_leaves.hpp"

namespace skinlab::data {

PreprocessOptions PreprocessOptions::from(const config::Node& node) {
  PreprocessOptions o;
  config::Fields f(node, "preprocess", {});
  f.optional("merge_tolerance", o.merge_tolerance);
  f.optional("min_vertices", o.min_vertices);
  f.optional("max_vertices", o.max_vertices);
  f.optional("top_k", o.top_k);
  f.optional("geodesic_radius", o.geodesic_radius);
  f.optional("geodesic_max_neighbours", o.geodesic_max_neighbours);
  o.leaf_bones = distances::LeafBoneOptions::from(f.section("leaf_bones"));
  f.optional("drop_weightless_leaves", o.drop_weightless_leaves);
  f.optional("drop_seed", o.drop_seed);
  f.optional("right_handed", o.right_handed);
  o.augment = AugmentOptions::from(f.section("augment"));
  const config::Node priors = f.section("priors");
  if (priors.exists()) {
    if (!priors.is_sequence()) priors.fail("expected a list of binder nodes ({type: <key>, ...})");
    std::set<std::string> types;
    for (std::size_t i = 0; i < priors.size(); ++i) {
      const config::Node node = priors[i];
      const std::string type = node.required_type("binder");
      if (!types.insert(type).second) {
        node.fail("prior '" + type + "' is listed twice (one entry per binder type)");
      }
      o.priors.push_back(node);
    }
  }
  f.check(o.merge_tolerance >= 0, "merge_tolerance", "must be ≥ 0");
  f.check(o.min_vertices >= 0, "min_vertices", "must be ≥ 0");
  f.check(o.max_vertices >= o.min_vertices, "max_vertices", "must be ≥ min_vertices");
  f.check(o.top_k >= 1, "top_k", "must be ≥ 1");
  f.check(o.geodesic_radius > 0, "geodesic_radius", "must be positive");
  f.check(o.geodesic_max_neighbours >= 0, "geodesic_max_neighbours", "must be ≥ 0");
  f.check(o.drop_weightless_leaves >= 0 && o.drop_weightless_leaves <= 1,
          "drop_weightless_leaves", "must be a probability in [0, 1]");
  f.finish();
  return o;
}

PreprocessOptions keep_prior(PreprocessOptions options, const std::string& keep) {
  std::vector<config::Node> kept;
  std::string listed;
  for (const auto& node : options.priors) {
    const std::string type = node.required_type("binder");
    listed += (listed.empty() ? "" : ", ") + type;
    if (type == keep) kept.push_back(node);
  }
  if (!keep.empty() && kept.empty()) {
    throw ConfigError("the model reads the prior '" + keep + "', which the preparation does not " +
                      "compute (its preprocess.priors: " + (listed.empty() ? "none" : listed) +
                      "); prepare the dataset with preprocess.priors: [{type: " + keep + "}]");
  }
  options.priors = std::move(kept);
  return options;
}

bool drops_weightless_leaves(const PreprocessOptions& options, const std::string& name) {
  if (options.drop_weightless_leaves <= 0) return false;
  // FNV-1a over the seed's bytes and the name: fixed across platforms, unlike std::hash.
  std::uint64_t h = 14695981039346656037ull;
  const auto mix = [&h](unsigned char byte) { h = (h ^ byte) * 1099511628211ull; };
  for (int i = 0; i < 8; ++i) mix(static_cast<unsigned char>(options.drop_seed >> (8 * i)));
  for (unsigned char ch : name) mix(ch);
  const double u = static_cast<double>(h >> 11) / static_cast<double>(1ull << 53);
  return u < options.drop_weightless_leaves;
}

void top_k_bones(const Eigen::MatrixXd& D, int k, RowMatrixXi& index, RowMatrixXf& distance) {
  if (k < 1) throw Error("top_k_bones: k must be ≥ 1, got " + std::to_string(k));
  const int nb = static_cast<int>(D.cols());
  const int kk = std::min(k, nb);
  index.resize(D.rows(), kk);
  distance.resize(D.rows(), kk);
  std::vector<int> order(nb);
  for (Eigen::Index v = 0; v < D.rows(); ++v) {
    std::iota(order.begin(), order.end(), 0);
    std::partial_sort(order.begin(), order.begin() + kk, order.end(),
                      [&](int a, int b) { return D(v, a) != D(v, b) ? D(v, a) < D(v, b) : a < b; });
    for (int j = 0; j < kk; ++j) {
      index(v, j) = order[j];
      distance(v, j) = static_cast<float>(D(v, order[j]));
    }
  }
}

Eigen::MatrixXd bone_weights(const geometry::SparseWeights& W, const geometry::Skeleton& skeleton,
                             const Eigen::MatrixXd& D) {
  const auto bones = skeleton.bones();
  std::vector<std::vector<int>> starting(skeleton.num_joints());
  for (std::size_t b = 0; b < bones.size(); ++b)
    starting[bones[b].start].push_back(static_cast<int>(b));
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(W.rows(), static_cast<Eigen::Index>(bones.size()));
  for (Eigen::Index v = 0; v < W.rows(); ++v) {
    for (geometry::SparseWeights::InnerIterator it(W, v); it; ++it) {
      int best = -1;
      for (int b : starting[it.col()]) {
        if (best < 0 || D(v, b) < D(v, best)) best = b;  // strict: ties keep the lower index
      }
      if (best >= 0) out(v, best) += it.value();
    }
  }
  return out;
}

namespace {

RowMatrixXi edge_rows(const Eigen::Matrix2Xi& edges) { return edges.transpose(); }

std::vector<float> rows_12(const Eigen::Matrix4d& m) {
  std::vector<float> out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out.push_back(static_cast<float>(m(r, c)));
  return out;
}

/// Per-joint global transforms as #J × 12 rows in the normalised frame. Conjugating by the
/// similarity keeps LBS exact there: (S·T·S⁻¹)(S·B·S⁻¹)⁻¹ = S·(T·B⁻¹)·S⁻¹.
void append_rows_12(const std::vector<Eigen::Isometry3d>& transforms, const Eigen::Matrix4d& sim,
                    const Eigen::Matrix4d& inv, std::vector<float>& out) {
  for (const auto& t : transforms) {
    const auto m = rows_12(sim * t.matrix() * inv);
    out.insert(out.end(), m.begin(), m.end());
  }
}

AnimationData convert(const datasets::Animation& a, const Eigen::Matrix4d& sim, int num_joints,
                      const std::string& where) {
  const Eigen::Matrix4d inv = sim.inverse();
  AnimationData out;
  out.name = a.name;
  out.fps = a.fps;
  out.num_frames = static_cast<int>(a.frames.size());
  if (static_cast<int>(a.bind.size()) != num_joints) {
    throw Error(where + ": animation '" + a.name + "' has " + std::to_string(a.bind.size()) +
                " bind transforms for " + std::to_string(num_joints) + " joints");
  }
  for (const auto& frame : a.frames) {
    if (static_cast<int>(frame.size()) != num_joints) {
      throw Error(where + ": animation '" + a.name + "' has a frame with " +
                  std::to_string(frame.size()) + " joints, expected " + std::to_string(num_joints));
    }
    append_rows_12(frame, sim, inv, out.frames);
  }
  append_rows_12(a.bind, sim, inv, out.bind);
  return out;
}

}  // namespace

PreparedCharacter preprocess(const datasets::SourceCharacter& as_read,
                             const std::vector<NamedDistance>& distances,
                             const PreprocessOptions& options, const PreprocessMode& mode,
                             PreprocessTimes* times) {
  // 0. The frame: a copy only where the character is mirrored (its clips can be large).
  std::optional<datasets::SourceCharacter> mirrored;
  if (options.right_handed && as_read.left_handed) {
    mirrored = as_read;
    datasets::make_right_handed(*mirrored);
  }
  const datasets::SourceCharacter& source = mirrored ? *mirrored : as_read;
  using Clock = std::chrono::steady_clock;
  auto lap = [last = Clock::now()](double* into) mutable {
    const auto now = Clock::now();
    if (into != nullptr) *into += std::chrono::duration<double>(now - last).count();
    last = now;
  };
  geometry::Character c = source.character;
  const std::string where = c.name + " (" + source.path + ")";
  const bool weighted = c.has_weights();
  if (!weighted && mode.require_weights) throw Error(where + ": character has no skin weights");

  // 0. The other convention of skeleton ends, for a share of the characters; only then are the
  // clips copied, to follow the kept joints.
  const std::vector<datasets::Animation>* clips = &source.animations;
  std::vector<datasets::Animation> reindexed;
  std::vector<Eigen::Isometry3d> bind = source.bind;
  if (weighted && drops_weightless_leaves(options, c.name)) {
    const std::vector<int> kept = geometry::drop_weightless_leaves(c);
    const auto keep = [&kept](const std::vector<Eigen::Isometry3d>& per_joint) {
      std::vector<Eigen::Isometry3d> out;
      for (int j : kept) {
        if (j < static_cast<int>(per_joint.size())) {
          out.push_back(per_joint[static_cast<std::size_t>(j)]);
        }
      }
      return out;
    };
    const std::size_t before = source.character.skeleton.names.size();
    if (bind.size() == before) bind = keep(bind);
    reindexed = source.animations;
    for (auto& a : reindexed) {  // a clip of another size stays as it is (reported below)
      if (a.bind.size() != before) continue;
      a.bind = keep(a.bind);
      for (auto& frame : a.frames) frame = keep(frame);
    }
    clips = &reindexed;
  }

  // 1. Normalise.
  geometry::NormalizeOptions normalize_options;
  normalize_options.source_up = source.up;
  const geometry::Similarity sim = geometry::normalize(c, normalize_options);

  // 2. Merge co-located vertices; average their weights.
  const geometry::MergedMesh merged = geometry::merge_vertices(c.mesh, {options.merge_tolerance});
  const geometry::SparseWeights W_merged =
      weighted ? geometry::average_vertex_data(c.weights, merged.old_to_new,
                                               merged.mesh.num_vertices())
               : geometry::SparseWeights();

  // 3. Subdivide small meshes; interpolate weights linearly.
  geometry::SubdividedMesh sub =
      geometry::subdivide(merged.mesh, {options.min_vertices, options.max_vertices});
  geometry::SparseWeights W;
  if (weighted) {
    W = (sub.S * W_merged).pruned();
    W.makeCompressed();
  }
  geometry::Mesh& mesh = sub.mesh;
  // 3b. Leaf bones on the final mesh (subdivision does not move the surface).
  distances::place_leaf_bones(mesh, c.skeleton, options.leaf_bones, where);
  // 3c. An augmented copy: the original's geometry, skeleton and leaf tips moved together.
  geometry::Similarity frame = sim;
  PreparedCharacter out;
  out.name = c.name;
  if (mode.augment_copy >= 0) {
    if (!weighted) throw Error(where + ": an augmented copy needs skin weights");
    out.name = augmented_name(c.name, mode.augment_copy);
    out.augmented_from = c.name;
    const Augmentation a = draw_augmentation(options.augment, c.name, mode.augment_copy,
                                             c.skeleton, *clips, sim.matrix());
    frame = augment(a, W, mesh, c.skeleton, out.name).after(sim);
  }
  lap(times != nullptr ? &times->normalise : nullptr);

  out.V = mesh.V;
  out.F = mesh.F;
  out.joint_names = c.skeleton.names;
  out.parents = c.skeleton.parents;
  out.joints = c.skeleton.positions;
  out.leaf_tips = c.skeleton.leaf_tips;
  const auto bones = c.skeleton.bones();
  out.bones.resize(static_cast<Eigen::Index>(bones.size()), 2);
  for (std::size_t b = 0; b < bones.size(); ++b) out.bones.row(b) << bones[b].start, bones[b].end;
  out.weights = W;
  out.vertex_map.assign(merged.old_to_new.data(),
                        merged.old_to_new.data() + merged.old_to_new.size());
  out.normalisation = frame.matrix();
  out.subdivision_levels = sub.levels;

  // 4. Distances, top-K candidates and bone-level targets.
  for (const auto& named : distances) {
    const Eigen::MatrixXd D = named.distance->compute(mesh, c.skeleton);
    if (D.rows() != mesh.V.rows() || D.cols() != static_cast<Eigen::Index>(bones.size())) {
      throw Error(where + ": distance '" + named.type + "' returned " + std::to_string(D.rows()) +
                  "×" + std::to_string(D.cols()) + ", expected #V×#B");
    }
    DistanceData d;
    d.D = D.cast<float>();
    // Top-K and targets from D as stored (float32), so that ties and orders recomputed from the
    // file agree with the stored top-K and targets.
    const Eigen::MatrixXd Ds = d.D.cast<double>();
    top_k_bones(Ds, options.top_k, d.topk_index, d.topk_distance);
    d.targets = RowMatrixXf::Zero(D.rows(), d.topk_index.cols());
    if (!weighted) {
      out.distances.emplace(named.type, std::move(d));
      continue;
    }
    const Eigen::MatrixXd Wb = bone_weights(W, c.skeleton, Ds);
    for (Eigen::Index v = 0; v < D.rows(); ++v) {
      for (Eigen::Index k = 0; k < d.topk_index.cols(); ++k) {
        d.targets(v, k) = static_cast<float>(Wb(v, d.topk_index(v, k)));
      }
    }
    out.distances.emplace(named.type, std::move(d));
  }

  // 4b. Priors: a binder's weights on the same mesh and bones.
  for (const auto& node : options.priors) {
    const std::string type = node.required_type("binder");
    const Eigen::MatrixXd P = binders::bind_checked(*binder_registry().create(node), mesh,
                                                    c.skeleton, "binder '" + type + "' on " + where);
    out.priors.emplace(type, P.cast<float>());
  }

  lap(times != nullptr ? &times->distance : nullptr);

  // 5. Graph structure and the Laplacian.
  out.one_ring_edges = edge_rows(geometry::one_ring(mesh).edges);
  geometry::GeodesicOptions geo;
  geo.radius = options.geodesic_radius;
  geo.max_neighbours = options.geodesic_max_neighbours;
  out.geodesic_edges = edge_rows(geometry::geodesic_neighbours(mesh, geo).edges);
  Eigen::SparseMatrix<double, Eigen::RowMajor> L(mesh.num_vertices(), mesh.num_vertices());
  if (mode.laplacian) L = geometry::laplacian(mesh);
  out.laplacian_indices.resize(L.nonZeros(), 2);
  out.laplacian_values.reserve(L.nonZeros());
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < L.outerSize(); ++i) {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(L, i); it; ++it, ++n) {
      out.laplacian_indices.row(n) << static_cast<int>(it.row()), static_cast<int>(it.col());
      out.laplacian_values.push_back(it.value());
    }
  }
  lap(times != nullptr ? &times->graph : nullptr);

  out.source = source.source;
  out.path = source.path;
  out.licence = source.licence;
  out.attribution = source.attribution;
  out.skeleton = source.skeleton;
  if (mode.augment_copy < 0) {  // an augmented copy is not in its source's bind pose
    if (!bind.empty()) {
      if (static_cast<int>(bind.size()) != c.skeleton.num_joints()) {
        throw Error(where + ": " + std::to_string(bind.size()) + " bind-pose transforms for " +
                    std::to_string(c.skeleton.num_joints()) + " joints");
      }
      const Eigen::Matrix4d sim_matrix = sim.matrix();
      append_rows_12(bind, sim_matrix, sim_matrix.inverse(), out.bind);
    }
    for (const auto& a : *clips) {
      out.animations.push_back(convert(a, sim.matrix(), c.skeleton.num_joints(), where));
    }
  }
  return out;
}

}  // namespace skinlab::data

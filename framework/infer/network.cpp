#include "framework/infer/network.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

#include "framework/core/error.hpp"

// Built for AVX2 and FMA (framework/CMakeLists.txt) while the rest of the program is not: its
// Eigen lives in a namespace of its own, so that none of its inline functions and template
// instances (other alignment, other allocation) can stand in for the others' at link time.
// Nothing of it crosses the interface (network.hpp).
#define Eigen skinlab_network_eigen
#include <Eigen/Core>

namespace skinlab::infer {

namespace fs = std::filesystem;

namespace {

using Matrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using IndexMatrix = Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using IndexMap = Eigen::Map<const IndexMatrix>;
using RowVector = Eigen::RowVectorXf;
using Index = Eigen::Index;
using Json = nlohmann::json;

/// LeakyReLU slope of every hidden layer (HeterSkinNet Sec. 4.2; graph::kLeakySlope).
constexpr float kSlope = 0.2f;
/// Rows per parallel block of a product.
constexpr Index kRowBlock = 128;

/// y = x·wt (+ y when `accumulate`), rows of x in parallel blocks; `wt` is in×out.
void product(const Eigen::Ref<const Matrix>& x, const Eigen::Ref<const Matrix>& wt, Matrix& y,
             bool accumulate = false) {
  if (!accumulate) y.resize(x.rows(), wt.cols());
  tbb::parallel_for(tbb::blocked_range<Index>(0, x.rows(), kRowBlock),
                    [&](const tbb::blocked_range<Index>& r) {
                      const Index n = r.end() - r.begin();
                      if (accumulate) {
                        y.middleRows(r.begin(), n).noalias() += x.middleRows(r.begin(), n) * wt;
                      } else {
                        y.middleRows(r.begin(), n).noalias() = x.middleRows(r.begin(), n) * wt;
                      }
                    });
}

void leaky_relu(Matrix& y) {
  float* v = y.data();
  const Index n = y.size();
  for (Index i = 0; i < n; ++i) v[i] = v[i] > 0 ? v[i] : v[i] * kSlope;
}

Matrix concat_columns(const std::vector<const Matrix*>& parts) {
  Index cols = 0;
  for (const Matrix* p : parts) cols += p->cols();
  Matrix out(parts.front()->rows(), cols);
  Index at = 0;
  for (const Matrix* p : parts) {
    out.middleCols(at, p->cols()) = *p;
    at += p->cols();
  }
  return out;
}

/// Compressed rows of an edge list: the neighbours j of each receiver i of the #E×2 rows (i, j).
struct Adjacency {
  std::vector<Index> start;  ///< #N + 1
  std::vector<int> neighbour;
  Index count(Index i) const { return start[i + 1] - start[i]; }
};

Adjacency adjacency(const IndexMap& edges, Index n, const std::string& who,
                    const char* set) {
  Adjacency a;
  a.start.assign(static_cast<std::size_t>(n) + 1, 0);
  for (Index e = 0; e < edges.rows(); ++e) {
    const int i = edges(e, 0), j = edges(e, 1);
    if (i < 0 || i >= n || j < 0 || j >= n) {
      throw Error(fmt::format("{}: {} edge {} is ({}, {}), but the graph has {} nodes", who, set, e,
                              i, j, n));
    }
    ++a.start[static_cast<std::size_t>(i) + 1];
  }
  for (Index i = 0; i < n; ++i) a.start[i + 1] += a.start[i];
  a.neighbour.resize(static_cast<std::size_t>(edges.rows()));
  std::vector<Index> fill(a.start.begin(), a.start.end() - 1);
  for (Index e = 0; e < edges.rows(); ++e) {
    a.neighbour[static_cast<std::size_t>(fill[edges(e, 0)]++)] = edges(e, 1);
  }
  return a;
}

/// The Skeleton Graph's edges (graph::skeleton_edges): bones a ≠ b sharing a joint.
IndexMatrix skeleton_edges(const IndexMap& bones) {
  std::vector<std::array<int, 2>> rows;
  for (Index a = 0; a < bones.rows(); ++a) {
    for (Index b = 0; b < bones.rows(); ++b) {
      if (a == b) continue;
      const bool share = bones(a, 0) == bones(b, 0) || bones(a, 0) == bones(b, 1) ||
                         bones(a, 1) == bones(b, 0) || bones(a, 1) == bones(b, 1);
      if (share) rows.push_back({static_cast<int>(a), static_cast<int>(b)});
    }
  }
  IndexMatrix out(static_cast<Index>(rows.size()), 2);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    out(static_cast<Index>(r), 0) = rows[r][0];
    out(static_cast<Index>(r), 1) = rows[r][1];
  }
  return out;
}

struct Graph {
  Index num_vertices = 0, num_bones = 0;
  Adjacency one_ring, geodesic, skeleton;
  const IndexMap* topk = nullptr;  ///< #V×K candidate bones

  const Adjacency& edges(const std::string& set) const {
    if (set == "one_ring") return one_ring;
    if (set == "geodesic") return geodesic;
    return skeleton;
  }
};

struct Features {
  Matrix vertex;  ///< #V×Fv
  Matrix bone;    ///< #B×Fb
};

/// Where the network's description comes from, for messages and for taking parameters.
class Source {
 public:
  Source(const ParameterFile& p, const fs::path& file) : p_(p), file_(file) {}

  [[noreturn]] void fail(const std::string& message) const {
    throw IoError(file_.string() + ": " + message);
  }

  /// `key` of the JSON object `node` (described as `where` in messages).
  const Json& field(const Json& node, const std::string& key, const std::string& where) const {
    if (!node.is_object() || !node.contains(key)) {
      fail(fmt::format("architecture: {} has no '{}'", where, key));
    }
    return node.at(key);
  }
  template <class T>
  T value(const Json& node, const std::string& key, const std::string& where) const {
    const Json& v = field(node, key, where);
    try {
      return v.get<T>();
    } catch (const nlohmann::json::exception&) {
      fail(fmt::format("architecture: {}'s '{}' is {}, of the wrong type", where, key, v.dump()));
    }
  }

  /// The parameter `name`, which must have `shape`; marked as used.
  const ParameterArray& take(const std::string& name, const std::vector<std::size_t>& shape) {
    const auto it = p_.parameters.find(name);
    if (it == p_.parameters.end()) fail(fmt::format("no parameter '{}'", name));
    if (it->second.shape != shape) {
      fail(fmt::format("parameter '{}' has shape [{}], expected [{}]", name,
                       fmt::join(it->second.shape, ", "), fmt::join(shape, ", ")));
    }
    used_.insert(name);
    return it->second;
  }

  /// Error for a parameter the network does not use (a file of another architecture).
  void check_all_used() const {
    for (const auto& [name, array] : p_.parameters) {
      if (!used_.count(name)) {
        fail(fmt::format("parameter '{}' is not used by the network its architecture describes",
                         name));
      }
    }
  }

  const Json& architecture() const { return p_.architecture; }

 private:
  const ParameterFile& p_;
  const fs::path& file_;
  std::set<std::string> used_;
};

struct Layer {
  Matrix wt;       ///< in×out: the transpose of libtorch's out×in weight
  RowVector bias;  ///< 1×out
};

/// graph::Mlp: Linear layers, LeakyReLU(0.2) after each but (unless activate_last) the last.
struct Mlp {
  Index in = 0;
  std::vector<Layer> layers;
  bool activate_last = true;

  /// The MLP at module path `path` (its entry of the architecture's `mlps`), taking `in`.
  static Mlp load(Source& s, const std::string& path, Index in) {
    const Json& mlps = s.field(s.architecture(), "mlps", "the architecture");
    const std::string where = "mlp '" + path + "'";
    const Json& node = s.field(mlps, path, "'mlps'");
    Mlp m;
    m.in = s.value<Index>(node, "in", where);
    if (m.in != in) {
      s.fail(fmt::format("architecture: {} takes {} inputs, but its input is {} wide", where, m.in,
                         in));
    }
    m.activate_last = s.value<bool>(node, "activate_last", where);
    Index width = in;
    const auto widths = s.value<std::vector<Index>>(node, "widths", where);
    for (std::size_t i = 0; i < widths.size(); ++i) {
      const std::string prefix = fmt::format("{}.linear{}.", path, i);
      const auto out = static_cast<std::size_t>(widths[i]);
      const ParameterArray& w = s.take(prefix + "weight", {out, static_cast<std::size_t>(width)});
      const ParameterArray& b = s.take(prefix + "bias", {out});
      Layer layer;
      layer.wt = Eigen::Map<const Matrix>(w.values.data(), widths[i], width).transpose();
      layer.bias = Eigen::Map<const RowVector>(b.values.data(), widths[i]);
      m.layers.push_back(std::move(layer));
      width = widths[i];
    }
    return m;
  }

  Index out_width() const { return layers.empty() ? in : layers.back().wt.cols(); }
  bool activated(std::size_t i) const { return i + 1 < layers.size() || activate_last; }

  /// Layers first..n−1 on x (MlpImpl::forward_from).
  Matrix forward_from(std::size_t first, Matrix x) const {
    for (std::size_t i = first; i < layers.size(); ++i) {
      Matrix y;
      product(x, layers[i].wt, y);
      y.rowwise() += layers[i].bias;
      if (activated(i)) leaky_relu(y);
      x = std::move(y);
    }
    return x;
  }
  Matrix forward(Matrix x) const { return forward_from(0, std::move(x)); }
};

/// MlpImpl::forward_gathered: the MLP on [own ‖ table[index(·,0)] ‖ … ‖ table[index(·,K−1)] ‖
/// shared], layer 0 split by the blocks of its weight. `shared` has one row (every vertex's) or
/// #V rows, or no columns.
struct GatheredMlp {
  Mlp mlp;
  Index own = 0, table = 0, k = 0, shared = 0;

  Matrix forward(const Matrix& own_rows, const Matrix& table_rows, const IndexMap& index,
                 const Matrix& shared_rows) const {
    const Index nv = own_rows.rows();
    if (mlp.layers.empty()) {  // the concatenation itself
      Matrix out(nv, own + k * table + shared);
      out.leftCols(own) = own_rows;
      for (Index v = 0; v < nv; ++v) {
        for (Index j = 0; j < k; ++j) out.row(v).segment(own + j * table, table) = table_rows.row(index(v, j));
        if (shared > 0) out.row(v).tail(shared) = shared_rows.row(shared_rows.rows() == 1 ? 0 : v);
      }
      return out;
    }
    const Matrix& wt = mlp.layers[0].wt;
    RowVector first_row = mlp.layers[0].bias;
    Matrix y;
    product(own_rows, wt.topRows(own), y);
    if (shared > 0 && shared_rows.rows() == 1) {
      first_row.noalias() += shared_rows * wt.bottomRows(shared);
    } else if (shared > 0) {
      product(shared_rows, wt.bottomRows(shared), y, /*accumulate=*/true);
    }
    std::vector<Matrix> per_bone(static_cast<std::size_t>(k));
    for (Index j = 0; j < k; ++j) {
      per_bone[j].noalias() = table_rows * wt.middleRows(own + j * table, table);
    }
    tbb::parallel_for(tbb::blocked_range<Index>(0, nv, 256), [&](const tbb::blocked_range<Index>& r) {
      for (Index v = r.begin(); v < r.end(); ++v) {
        auto row = y.row(v);
        row += first_row;
        for (Index j = 0; j < k; ++j) row += per_bone[static_cast<std::size_t>(j)].row(index(v, j));
      }
    });
    if (mlp.activated(0)) leaky_relu(y);
    return mlp.forward_from(1, std::move(y));
  }
};

/// graph::edge_conv_max (Eq. 2, with the self-loop unless `self_loops` is false).
struct EdgeMlp {
  Mlp mlp;
  Matrix wa, w2;  ///< F×F1 each: (W₁ + W₂)ᵀ and W₂ᵀ of layer 0
  bool self_loops = true;

  static EdgeMlp load(Source& s, const std::string& path, Index width, bool self_loops) {
    EdgeMlp e;
    e.mlp = Mlp::load(s, path, 2 * width);
    if (e.mlp.layers.empty()) s.fail("architecture: EdgeConv mlp '" + path + "' has no layer");
    const Matrix& wt = e.mlp.layers[0].wt;
    e.w2 = wt.bottomRows(width);
    e.wa = wt.topRows(width) + e.w2;
    e.self_loops = self_loops;
    return e;
  }

  Matrix forward(const Matrix& x, const Adjacency& adj) const {
    const Index n = x.rows();
    Matrix a, b;
    product(x, wa, a);
    a.rowwise() += mlp.layers[0].bias;
    product(x, w2, b);
    const Index f = a.cols();
    if (mlp.layers.size() == 1) {
      // max_j σ(a_i − b_j) = σ(a_i − min_j b_j): σ is non-decreasing.
      Matrix out(n, f);
      tbb::parallel_for(tbb::blocked_range<Index>(0, n, 256), [&](const tbb::blocked_range<Index>& r) {
        RowVector least(f);
        for (Index i = r.begin(); i < r.end(); ++i) {
          if (!self_loops && adj.count(i) == 0) {
            out.row(i).setZero();
            continue;
          }
          least.setConstant(std::numeric_limits<float>::infinity());
          for (Index e = adj.start[i]; e < adj.start[i + 1]; ++e) {
            least = least.cwiseMin(b.row(adj.neighbour[static_cast<std::size_t>(e)]));
          }
          if (self_loops) least = least.cwiseMin(b.row(i));
          out.row(i) = a.row(i) - least;
        }
      });
      if (mlp.activated(0)) leaky_relu(out);
      return out;
    }
    // Deeper MLPs: one message per edge, max per receiver (and the self-loop's message).
    const auto edges = static_cast<Index>(adj.neighbour.size());
    Matrix messages(edges, f);
    for (Index i = 0; i < n; ++i) {
      for (Index e = adj.start[i]; e < adj.start[i + 1]; ++e) {
        messages.row(e) = a.row(i) - b.row(adj.neighbour[static_cast<std::size_t>(e)]);
      }
    }
    if (mlp.activated(0)) leaky_relu(messages);
    messages = mlp.forward_from(1, std::move(messages));
    Matrix out = Matrix::Constant(n, mlp.out_width(), -std::numeric_limits<float>::infinity());
    for (Index i = 0; i < n; ++i) {
      for (Index e = adj.start[i]; e < adj.start[i + 1]; ++e) {
        out.row(i) = out.row(i).cwiseMax(messages.row(e));
      }
    }
    if (self_loops) {
      Matrix own = a - b;
      if (mlp.activated(0)) leaky_relu(own);
      return out.cwiseMax(mlp.forward_from(1, std::move(own)));
    }
    for (Index i = 0; i < n; ++i) {
      if (adj.count(i) == 0) out.row(i).setZero();
    }
    return out;
  }
};

// ---- the ops -------------------------------------------------------------------------------

struct Widths {
  Index vertex = 0, bone = 0, k = 0;
};

class Op {
 public:
  virtual ~Op() = default;
  virtual Features forward(Features in, const Graph& g) const = 0;
};

bool edge_set_of_bones(const std::string& set) { return set == "skeleton"; }

std::string edge_set(Source& s, const Json& node, const std::string& where) {
  auto set = s.value<std::string>(node, "edges", where);
  if (set != "one_ring" && set != "geodesic" && set != "skeleton") {
    s.fail(fmt::format("architecture: {} runs on unknown edge set '{}'", where, set));
  }
  return set;
}

void need(Source& s, bool ok, const std::string& where, const std::string& what) {
  if (!ok) s.fail(fmt::format("architecture: {} needs {}", where, what));
}

/// `b2v` (Eq. 5).
class B2v final : public Op {
 public:
  B2v(Source& s, const std::string& path, Widths& w) {
    need(s, w.vertex >= 1 && w.bone >= 1 && w.k >= 1, "op '" + path + "'",
         "vertex and bone features and K ≥ 1");
    mlp_.mlp = Mlp::load(s, path + ".mlp", w.vertex + w.k * w.bone);
    mlp_.own = w.vertex;
    mlp_.table = w.bone;
    mlp_.k = w.k;
    w.vertex = mlp_.mlp.out_width();
  }
  Features forward(Features in, const Graph& g) const override {
    in.vertex = mlp_.forward(in.vertex, in.bone, *g.topk, Matrix());
    return in;
  }

 private:
  GatheredMlp mlp_;
};

/// `v2b` (Eq. 4).
class V2b final : public Op {
 public:
  V2b(Source& s, const std::string& path, const Json& node, Widths& w) {
    need(s, w.vertex >= 1 && w.bone >= 1 && w.k >= 1, "op '" + path + "'",
         "vertex and bone features and K ≥ 1");
    scale_ = s.value<float>(node, "variance_scale", "op '" + path + "'");
    mlp_ = Mlp::load(s, path + ".mlp", w.bone + 3 * w.vertex);
    w.bone = mlp_.out_width();
  }
  Features forward(Features in, const Graph& g) const override {
    const Matrix& x = in.vertex;
    const IndexMap& index = *g.topk;
    const Index nb = g.num_bones, f = x.cols(), k = index.cols();
    // [max ‖ mean ‖ scale·var] per bone, accumulated over the (vertex, candidate) pairs in
    // row-major order as graph::pool_vertices_to_bones does.
    std::vector<Index> count(static_cast<std::size_t>(nb), 0);
    for (Index v = 0; v < index.rows(); ++v) {
      for (Index j = 0; j < k; ++j) ++count[static_cast<std::size_t>(index(v, j))];
    }
    Matrix max = Matrix::Constant(nb, f, -std::numeric_limits<float>::infinity());
    Matrix mean = Matrix::Zero(nb, f), var = Matrix::Zero(nb, f);
    for (Index v = 0; v < index.rows(); ++v) {
      for (Index j = 0; j < k; ++j) {
        const Index b = index(v, j);
        max.row(b) = max.row(b).cwiseMax(x.row(v));
        mean.row(b) += x.row(v);
      }
    }
    for (Index b = 0; b < nb; ++b) {
      const auto n = static_cast<float>(std::max<Index>(count[static_cast<std::size_t>(b)], 1));
      if (count[static_cast<std::size_t>(b)] == 0) max.row(b).setZero();
      mean.row(b) /= n;
    }
    for (Index v = 0; v < index.rows(); ++v) {
      for (Index j = 0; j < k; ++j) {
        const Index b = index(v, j);
        var.row(b) += (x.row(v) - mean.row(b)).cwiseAbs2();
      }
    }
    for (Index b = 0; b < nb; ++b) {
      const auto n = static_cast<float>(std::max<Index>(count[static_cast<std::size_t>(b)], 1));
      var.row(b) = var.row(b) / n * scale_;
    }
    in.bone = mlp_.forward(concat_columns({&in.bone, &max, &mean, &var}));
    return in;
  }

 private:
  float scale_ = 0.1f;
  Mlp mlp_;
};

/// `edge_conv` (Eq. 2) on one edge set.
class EdgeConv final : public Op {
 public:
  EdgeConv(Source& s, const std::string& path, const Json& node, Widths& w) {
    const std::string where = "op '" + path + "'";
    set_ = edge_set(s, node, where);
    Index& width = edge_set_of_bones(set_) ? w.bone : w.vertex;
    need(s, width >= 1, where, "features on its edge set's nodes");
    mlp_ = EdgeMlp::load(s, path + ".mlp", width, s.value<bool>(node, "self_loops", where));
    width = mlp_.mlp.out_width();
  }
  Features forward(Features in, const Graph& g) const override {
    Matrix& x = edge_set_of_bones(set_) ? in.bone : in.vertex;
    x = mlp_.forward(x, g.edges(set_));
    return in;
  }

 private:
  std::string set_;
  EdgeMlp mlp_;
};

/// `mesh_conv` (Eq. 3).
class MeshConv final : public Op {
 public:
  MeshConv(Source& s, const std::string& path, const Json& node, Widths& w) {
    const std::string where = "op '" + path + "'";
    need(s, w.vertex >= 1, where, "vertex features");
    const bool self_loops = s.value<bool>(node, "self_loops", where);
    Index concatenated = 0;
    for (const auto& set : s.value<std::vector<std::string>>(node, "edges", where)) {
      if (set != "one_ring" && set != "geodesic") {
        s.fail(fmt::format("architecture: {} runs on '{}', not a mesh edge set", where, set));
      }
      sets_.push_back(set);
      branches_.push_back(EdgeMlp::load(s, path + ".edge_mlp_" + set, w.vertex, self_loops));
      concatenated += branches_.back().mlp.out_width();
    }
    need(s, !sets_.empty(), where, "at least one edge set");
    mlp_ = Mlp::load(s, path + ".mlp", concatenated);
    w.vertex = mlp_.out_width();
  }
  Features forward(Features in, const Graph& g) const override {
    std::vector<Matrix> outs;
    for (std::size_t i = 0; i < sets_.size(); ++i) {
      outs.push_back(branches_[i].forward(in.vertex, g.edges(sets_[i])));
    }
    std::vector<const Matrix*> parts;
    for (const Matrix& m : outs) parts.push_back(&m);
    in.vertex = mlp_.forward(outs.size() == 1 ? std::move(outs[0]) : concat_columns(parts));
    return in;
  }

 private:
  std::vector<std::string> sets_;
  std::vector<EdgeMlp> branches_;
  Mlp mlp_;
};

/// `global_pool` (Fig. 3's global branch).
class GlobalPool final : public Op {
 public:
  GlobalPool(Source& s, const std::string& path, const Json& node, Widths& w) {
    const std::string where = "op '" + path + "'";
    const auto order = s.value<std::string>(node, "order", where);
    if (order != "mlp_max" && order != "max_mlp") {
      s.fail(fmt::format("architecture: {} has unknown order '{}'", where, order));
    }
    mlp_first_ = order == "mlp_max";
    keep_input_ = s.value<bool>(node, "keep_input", where);
    Index global = 0;
    for (const auto& kind : s.value<std::vector<std::string>>(node, "pool", where)) {
      if (kind != "vertex" && kind != "bone") {
        s.fail(fmt::format("architecture: {} pools unknown node type '{}'", where, kind));
      }
      const bool vertex = kind == "vertex";
      const Index width = vertex ? w.vertex : w.bone;
      need(s, width >= 1, where, kind + " features to pool");
      pools_.push_back({vertex, Mlp::load(s, path + (vertex ? ".vertex_mlp" : ".bone_mlp"), width)});
      global += pools_.back().mlp.out_width();
    }
    for (const auto& kind : s.value<std::vector<std::string>>(node, "to", where)) {
      if (kind == "vertex") {
        to_vertex_ = true;
      } else if (kind == "bone") {
        to_bone_ = true;
      } else {
        s.fail(fmt::format("architecture: {} broadcasts to unknown node type '{}'", where, kind));
      }
    }
    if (to_vertex_) w.vertex = (keep_input_ ? w.vertex : 0) + global;
    if (to_bone_) w.bone = (keep_input_ ? w.bone : 0) + global;
  }

  /// G = g_1 ‖ g_2 ‖ … (1×width), one part per pooled subgraph.
  RowVector global(const Features& in) const {
    std::vector<RowVector> parts;
    Index width = 0;
    for (const Pool& p : pools_) {
      const Matrix& x = p.vertex ? in.vertex : in.bone;
      parts.push_back(mlp_first_ ? RowVector(p.mlp.forward(x).colwise().maxCoeff())
                                 : RowVector(p.mlp.forward(Matrix(x.colwise().maxCoeff()))));
      width += parts.back().size();
    }
    RowVector g(width);
    Index at = 0;
    for (const RowVector& p : parts) {
      g.segment(at, p.size()) = p;
      at += p.size();
    }
    return g;
  }

  /// The receiving nodes get G as their features (and keep theirs when keep_input).
  bool broadcasts_alone_to_vertices() const { return to_vertex_ && !keep_input_; }

  Features forward(Features in, const Graph&) const override {
    const RowVector g = global(in);
    const auto receive = [&](const Matrix& own) {
      Matrix broadcast = g.replicate(own.rows(), 1);
      return keep_input_ ? concat_columns({&own, &broadcast}) : broadcast;
    };
    Features out = in;
    if (to_vertex_) out.vertex = receive(in.vertex);
    if (to_bone_) out.bone = receive(in.bone);
    return out;
  }

 private:
  struct Pool {
    bool vertex;
    Mlp mlp;
  };
  std::vector<Pool> pools_;
  bool mlp_first_ = true, keep_input_ = true, to_vertex_ = false, to_bone_ = false;
};

const char* const kSupported = "b2v, v2b, edge_conv, mesh_conv, global_pool";

std::unique_ptr<Op> make_op(Source& s, const std::string& path, const Json& node, Widths& w) {
  const auto type = s.value<std::string>(node, "type", "op '" + path + "'");
  if (type == "b2v") return std::make_unique<B2v>(s, path, w);
  if (type == "v2b") return std::make_unique<V2b>(s, path, node, w);
  if (type == "edge_conv") return std::make_unique<EdgeConv>(s, path, node, w);
  if (type == "mesh_conv") return std::make_unique<MeshConv>(s, path, node, w);
  if (type == "global_pool") return std::make_unique<GlobalPool>(s, path, node, w);
  s.fail(fmt::format("op '{}' (type {}) is not implemented by the Eigen forward pass of "
                     "skinlab-predict (it implements {}); use skinlab predict",
                     path, type, kSupported));
}

std::vector<std::unique_ptr<Op>> make_sequence(Source& s, const std::string& name, Widths& w) {
  const Json& list = s.field(s.architecture(), name, "the architecture");
  if (!list.is_array()) s.fail("architecture: '" + name + "' is not a list of ops");
  std::vector<std::unique_ptr<Op>> ops;
  for (const Json& node : list) {
    const auto op_name = s.value<std::string>(node, "name", "an op of '" + name + "'");
    ops.push_back(make_op(s, name + "." + op_name, node, w));
  }
  return ops;
}

Features run(const std::vector<std::unique_ptr<Op>>& ops, Features x, const Graph& g) {
  for (const auto& op : ops) x = op->forward(std::move(x), g);
  return x;
}

void softmax_rows(Matrix& m) {
  for (Index v = 0; v < m.rows(); ++v) {
    auto row = m.row(v);
    row.array() = (row.array() - row.maxCoeff()).exp();
    row /= row.sum();
  }
}

}  // namespace

struct Network::Impl {
  Index top_k = 0;
  std::string prior;  ///< empty: the model reads none
  bool prior_bias = false;
  float prior_epsilon = 0;
  bool keep_prior_outside = false;
  double prior_mix = 0;
  float leaf_bias = 0;  ///< models::BranchedModelOptions::leaf_bias
  double distance_unit = 1.0 / 88.0, min_distance = 1.0;
  std::vector<std::unique_ptr<Op>> stem, local;
  std::unique_ptr<Op> global;
  const GlobalPool* global_pool = nullptr;  ///< `global` when it broadcasts G alone
  GatheredMlp head;
};

Network::Network(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Network::Network(Network&&) noexcept = default;
Network& Network::operator=(Network&&) noexcept = default;
Network::~Network() = default;

int Network::top_k() const { return static_cast<int>(impl_->top_k); }
const std::string& Network::prior() const { return impl_->prior; }
bool Network::keep_prior_outside() const { return impl_->keep_prior_outside; }
double Network::prior_mix() const { return impl_->prior_mix; }

Network Network::from(const ParameterFile& parameters, const fs::path& file) {
#if defined(__AVX2__) && defined(__FMA__)
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) {
    throw Error("skinlab-predict was built for AVX2 and FMA, which this processor lacks; build "
                "it again on this machine");
  }
#endif
  Source s(parameters, file);
  if (parameters.model != "heterskinnet") {
    s.fail(fmt::format("model '{}' is not implemented by the Eigen forward pass of "
                       "skinlab-predict (it implements heterskinnet); use skinlab predict",
                       parameters.model));
  }
  const Json& arch = parameters.architecture;
  auto impl = std::make_unique<Impl>();
  if (arch.contains("prior")) {
    impl->prior = s.value<std::string>(arch, "prior", "the architecture");
    impl->prior_bias = s.value<bool>(arch, "prior_bias", "the architecture");
    const auto epsilon = s.value<double>(arch, "prior_epsilon", "the architecture");
    if (impl->prior.empty() || !(epsilon > 0)) {
      s.fail("architecture: prior must name a binder and prior_epsilon be positive");
    }
    impl->prior_epsilon = static_cast<float>(epsilon);
    // Parameter files written before keep_prior_outside existed do not have it: false.
    if (arch.contains("keep_prior_outside")) {
      impl->keep_prior_outside = s.value<bool>(arch, "keep_prior_outside", "the architecture");
    }
    // Written only when not 0 (and never before prior_mix existed).
    if (arch.contains("prior_mix")) {
      impl->prior_mix = s.value<double>(arch, "prior_mix", "the architecture");
      if (!(impl->prior_mix >= 0 && impl->prior_mix <= 1)) {
        s.fail(fmt::format("architecture: prior_mix must be in [0, 1], got {}", impl->prior_mix));
      }
    }
  }
  impl->top_k = s.value<Index>(arch, "top_k", "the architecture");
  impl->distance_unit = s.value<double>(arch, "distance_unit", "the architecture");
  impl->min_distance = s.value<double>(arch, "min_distance", "the architecture");
  // Written only when not 0 (and never before leaf_bias existed).
  if (arch.contains("leaf_bias")) {
    const auto bias = s.value<double>(arch, "leaf_bias", "the architecture");
    if (!std::isfinite(bias)) s.fail("architecture: leaf_bias must be finite");
    impl->leaf_bias = static_cast<float>(bias);
  }
  if (impl->top_k < 1 || !(impl->distance_unit > 0) || !(impl->min_distance > 0)) {
    s.fail("architecture: top_k, distance_unit and min_distance must be positive");
  }
  const Index prior_inputs = impl->prior.empty() ? 0 : impl->top_k;
  Widths w{impl->top_k + 3 + prior_inputs, 6, impl->top_k};
  impl->stem = make_sequence(s, "stem", w);
  Widths g = w;
  impl->global = make_op(s, "global_branch",
                         s.field(arch, "global_branch", "the architecture"), g);
  const auto* pool = dynamic_cast<const GlobalPool*>(impl->global.get());
  if (pool != nullptr && pool->broadcasts_alone_to_vertices()) impl->global_pool = pool;
  Widths l = w;
  impl->local = make_sequence(s, "local", l);
  need(s, l.vertex >= 1 && l.bone >= 1, "the local branch", "to end with vertex and bone features");
  impl->head.own = l.vertex;
  impl->head.table = l.bone;
  impl->head.k = impl->top_k;
  impl->head.shared = g.vertex;
  impl->head.mlp = Mlp::load(s, "head", l.vertex + impl->top_k * l.bone + g.vertex);
  if (impl->head.mlp.out_width() != impl->top_k) {
    s.fail(fmt::format("architecture: the head gives {} outputs, not K = {}",
                       impl->head.mlp.out_width(), impl->top_k));
  }
  s.check_all_used();
  return Network(std::move(impl));
}

namespace {

/// The #V×k_own row-major `own` with its first column repeated until it has `k` columns.
template <typename T>
std::vector<T> repeat_nearest(const T* own, Index nv, Index k_own, Index k) {
  std::vector<T> out(static_cast<std::size_t>(nv * k));
  for (Index v = 0; v < nv; ++v)
    for (Index j = 0; j < k; ++j) out[v * k + j] = own[v * k_own + (j < k_own ? j : 0)];
  return out;
}

}  // namespace

std::vector<float> Network::forward(const NetworkInput& character) const {
  const Impl& n = *impl_;
  const Index nv = character.num_vertices, nb = character.num_bones;
  // As the libtorch model (experiments/heterskinnet/heterskinnet.cpp): a character with fewer
  // bones than K has that many candidates; they are padded with the nearest one again and the
  // padded slots are dropped before the softmax.
  const Index k_own = character.top_k;
  if (k_own != n.top_k && !(k_own >= 1 && k_own < n.top_k && k_own == nb)) {
    throw Error(fmt::format("{}: {} candidate bones per vertex and {} bones, but the model was "
                            "built for K = {}",
                            character.name, k_own, nb, n.top_k));
  }
  NetworkInput c = character;
  std::vector<int> padded_index;
  std::vector<float> padded_distance, padded_prior;
  if (k_own < n.top_k) {
    padded_index = repeat_nearest(character.topk_index, nv, k_own, n.top_k);
    padded_distance = repeat_nearest(character.topk_distance, nv, k_own, n.top_k);
    c.topk_index = padded_index.data();
    c.topk_distance = padded_distance.data();
    if (character.prior != nullptr) {
      padded_prior = repeat_nearest(character.prior, nv, k_own, n.top_k);
      c.prior = padded_prior.data();
    }
    c.top_k = n.top_k;
  }
  if (nv < 1 || nb < 1) {
    throw Error(fmt::format("{}: {} vertices and {} bones; the network needs both", c.name, nv,
                            nb));
  }
  if (!n.prior.empty() && c.prior == nullptr) {
    throw Error(fmt::format("{}: the model reads the '{}' prior, which was not computed for it",
                            c.name, n.prior));
  }
  const IndexMap topk(c.topk_index, nv, n.top_k);
  for (Index v = 0; v < nv; ++v) {
    for (Index j = 0; j < n.top_k; ++j) {
      if (topk(v, j) < 0 || topk(v, j) >= nb) {
        throw Error(fmt::format("{}: candidate {} of vertex {} is {}, not one of the {} bones",
                                c.name, j, v, topk(v, j), nb));
      }
    }
  }
  const IndexMap bones(c.bones, nb, 2);
  Graph g;
  g.num_vertices = nv;
  g.num_bones = nb;
  g.topk = &topk;
  g.one_ring = adjacency(IndexMap(c.one_ring, c.num_one_ring, 2), nv, c.name, "one_ring");
  g.geodesic = adjacency(IndexMap(c.geodesic, c.num_geodesic, 2), nv, c.name, "geodesic");
  const IndexMatrix skeleton = skeleton_edges(bones);
  g.skeleton = adjacency(IndexMap(skeleton.data(), skeleton.rows(), 2), nb, c.name, "skeleton");

  // Sec. 3.2's attributes: f_v = [p, 1/D] with D in distance units, clamped; f_b = [start, end].
  using DoubleMap = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic,
                                                   Eigen::RowMajor>>;
  const Eigen::Map<const Matrix> distance(c.topk_distance, nv, n.top_k);
  const Index prior_inputs = n.prior.empty() ? 0 : n.top_k;
  Features x;
  x.vertex.resize(nv, 3 + n.top_k + prior_inputs);
  x.vertex.leftCols(3) = DoubleMap(c.positions, nv, 3).cast<float>();
  const auto unit = static_cast<float>(n.distance_unit);
  const auto least = static_cast<float>(n.min_distance);
  for (Index v = 0; v < nv; ++v) {
    for (Index j = 0; j < n.top_k; ++j) {
      x.vertex(v, 3 + j) = 1.0f / std::max(distance(v, j) / unit, least);
    }
  }
  Matrix prior;  // #V×K
  if (prior_inputs > 0) {
    prior = Eigen::Map<const Matrix>(c.prior, nv, n.top_k);
    x.vertex.rightCols(prior_inputs) = prior;
  }
  x.bone = DoubleMap(c.bone_segments, nb, 6).cast<float>();

  x = run(n.stem, std::move(x), g);
  Matrix shared;
  if (n.global_pool != nullptr) {
    shared = n.global_pool->global(x);  // one row, every vertex's
  } else {
    shared = n.global->forward(x, g).vertex;
  }
  const Features l = run(n.local, std::move(x), g);
  Matrix out = n.head.forward(l.vertex, l.bone, topk, shared);
  if (prior_inputs > 0 && n.prior_bias) out.array() += (prior.array() + n.prior_epsilon).log();
  if (n.leaf_bias != 0) {  // models::with_leaf_bias: on the candidates that are a leaf's bone
    for (Index v = 0; v < nv; ++v)
      for (Index j = 0; j < n.top_k; ++j)
        if (bones(topk(v, j), 0) == bones(topk(v, j), 1)) out(v, j) += n.leaf_bias;
  }
  if (k_own < n.top_k) out = Matrix(out.leftCols(k_own));
  softmax_rows(out);
  return std::vector<float>(out.data(), out.data() + out.size());
}

}  // namespace skinlab::infer

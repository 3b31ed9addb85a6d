#include "framework/data/dataset_file.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "framework/core/error.hpp"

namespace skinlab::data {

namespace {

std::string group_of(const std::string& name) { return "/characters/" + name; }

void check_name(const std::filesystem::path& file, const std::string& name) {
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos) {
    throw IoError(file.string() + ": character name '" + name +
                  "' cannot be an HDF5 group name (empty, '.', or contains '/')");
  }
}

/// The per-joint transform arrays hold what their shapes will claim (the writer reads
/// #J×12 values per pose from them).
void check_transforms(const std::filesystem::path& file, const PreparedCharacter& c) {
  const std::size_t per_pose = static_cast<std::size_t>(c.num_joints()) * 12;
  if (!c.bind.empty() && c.bind.size() != per_pose) {
    throw IoError(file.string() + ": character '" + c.name + "': bind pose of " +
                  std::to_string(c.bind.size()) + " values, expected #J×12 = " +
                  std::to_string(per_pose));
  }
  for (const AnimationData& anim : c.animations) {
    if (anim.bind.size() != per_pose ||
        anim.frames.size() != per_pose * static_cast<std::size_t>(anim.num_frames)) {
      throw IoError(file.string() + ": character '" + c.name + "': clip '" + anim.name +
                    "' holds " + std::to_string(anim.frames.size()) + " frame and " +
                    std::to_string(anim.bind.size()) + " bind values, expected " +
                    std::to_string(anim.num_frames) + "×#J×12 and #J×12 (#J = " +
                    std::to_string(c.num_joints()) + ")");
    }
  }
}

void write_character(H5Writer& w, const PreparedCharacter& c) {
  const std::string g = group_of(c.name);
  w.create_group(g);
  w.write(g + "/V", c.V);
  w.write(g + "/F", c.F);
  w.write_strings(g + "/joint_names", c.joint_names);
  w.write(g + "/parents", c.parents);
  w.write(g + "/joints", c.joints);
  w.write(g + "/bones", c.bones);
  if (c.leaf_tips.size() > 0) w.write(g + "/leaf_tips", c.leaf_tips);
  // CSR of the row-major #V×#J weights.
  geometry::SparseWeights W = c.weights;
  W.makeCompressed();
  std::vector<int> indptr(W.outerIndexPtr(), W.outerIndexPtr() + W.rows() + 1);
  std::vector<int> indices(W.innerIndexPtr(), W.innerIndexPtr() + W.nonZeros());
  std::vector<float> values(W.valuePtr(), W.valuePtr() + W.nonZeros());
  if (W.rows() == 0) indptr = {0};
  w.write(g + "/weights/indptr", indptr);
  w.write(g + "/weights/indices", indices);
  w.write(g + "/weights/values", values);
  w.write_attribute(g + "/weights", "num_joints", static_cast<std::int64_t>(c.num_joints()));
  w.write(g + "/vertex_map", c.vertex_map);
  w.write(g + "/normalisation", RowMatrixXd(c.normalisation));
  for (const auto& [type, d] : c.distances) {
    const std::string dg = g + "/distances/" + type;
    w.write(dg + "/D", d.D);
    w.write(dg + "/topk_index", d.topk_index);
    w.write(dg + "/topk_distance", d.topk_distance);
    w.write(dg + "/targets", d.targets);
  }
  w.create_group(g + "/distances");
  for (const auto& [type, P] : c.priors) w.write(g + "/priors/" + type, P);
  w.write(g + "/edges/one_ring", c.one_ring_edges);
  w.write(g + "/edges/geodesic", c.geodesic_edges);
  w.write(g + "/laplacian/indices", c.laplacian_indices);
  w.write(g + "/laplacian/values", c.laplacian_values);
  w.write_attribute(g, "source", c.source);
  w.write_attribute(g, "path", c.path);
  w.write_attribute(g, "licence", c.licence);
  w.write_attribute(g, "attribution", c.attribution);
  w.write_attribute(g, "skeleton", c.skeleton);
  w.write_attribute(g, "group", c.variant_group());
  if (c.is_augmented_copy()) w.write_attribute(g, "augmented_from", c.augmented_from);
  w.write_attribute(g, "subdivision_levels", static_cast<std::int64_t>(c.subdivision_levels));
  if (!c.bind.empty()) {
    w.write(g + "/bind", {static_cast<std::size_t>(c.num_joints()), 12}, c.bind.data());
  }
  w.create_group(g + "/animations");
  for (std::size_t a = 0; a < c.animations.size(); ++a) {
    const AnimationData& anim = c.animations[a];
    const std::string ag = g + "/animations/" + std::to_string(a);
    w.write(
        ag + "/frames",
        {static_cast<std::size_t>(anim.num_frames), static_cast<std::size_t>(c.num_joints()), 12},
        anim.frames.data());
    w.write(ag + "/bind", {static_cast<std::size_t>(c.num_joints()), 12}, anim.bind.data());
    w.write_attribute(ag, "name", anim.name);
    w.write_attribute(ag, "fps", anim.fps);
  }
}

// ---- validation --------------------------------------------------------------------------------

class Checker {
 public:
  explicit Checker(const H5Reader& r) : r_(r) {}

  [[noreturn]] void fail(const std::string& dataset, const std::string& message) const {
    throw IoError(r_.path().string() + ": dataset '" + dataset + "': " + message);
  }

  /// `rows`/`cols` < 0: any.
  template <class Matrix>
  void shape(const std::string& name, const Matrix& m, long rows, long cols) const {
    if ((rows >= 0 && m.rows() != rows) || (cols >= 0 && m.cols() != cols)) {
      fail(name, "shape " + std::to_string(m.rows()) + "×" + std::to_string(m.cols()) +
                     ", expected " + (rows >= 0 ? std::to_string(rows) : std::string("any")) + "×" +
                     (cols >= 0 ? std::to_string(cols) : std::string("any")));
    }
  }
  void length(const std::string& name, std::size_t n, std::size_t expected) const {
    if (n != expected) {
      fail(name, "length " + std::to_string(n) + ", expected " + std::to_string(expected));
    }
  }
  template <class Range>
  void indices(const std::string& name, const Range& values, long lo, long hi,
               const std::string& what) const {
    long i = 0;
    for (const auto v : values) {
      if (v < lo || v >= hi) {
        fail(name, "entry " + std::to_string(i) + " = " + std::to_string(v) + " is not a valid " +
                       what + " index (range [" + std::to_string(lo) + ", " + std::to_string(hi) +
                       "))");
      }
      ++i;
    }
  }
  template <class Range>
  void finite(const std::string& name, const Range& values) const {
    long i = 0;
    for (const auto v : values) {
      if (!std::isfinite(static_cast<double>(v))) {
        fail(name, "entry " + std::to_string(i) + " is not finite");
      }
      ++i;
    }
  }

 private:
  const H5Reader& r_;
};

template <class Matrix>
std::vector<typename Matrix::Scalar> values_of(const Matrix& m) {
  return {m.data(), m.data() + m.size()};
}

PreparedCharacter read_character(const H5Reader& r, const std::string& name) {
  const Checker check(r);
  const std::string g = group_of(name);
  if (!r.has(g)) check.fail(g, "character listed in /character_names has no group");
  PreparedCharacter c;
  c.name = name;
  c.V = r.read_double(g + "/V");
  check.shape(g + "/V", c.V, -1, 3);
  if (c.V.rows() == 0) check.fail(g + "/V", "no vertices");
  check.finite(g + "/V", values_of(c.V));
  const long nv = c.V.rows();
  c.F = r.read_int(g + "/F");
  check.shape(g + "/F", c.F, -1, 3);
  check.indices(g + "/F", values_of(c.F), 0, nv, "vertex");
  c.joint_names = r.read_strings(g + "/joint_names");
  const long nj = static_cast<long>(c.joint_names.size());
  if (nj == 0) check.fail(g + "/joint_names", "no joints");
  c.parents = r.read_ints(g + "/parents");
  check.length(g + "/parents", c.parents.size(), nj);
  check.indices(g + "/parents", c.parents, -1, nj, "parent joint");
  c.joints = r.read_double(g + "/joints");
  check.shape(g + "/joints", c.joints, nj, 3);
  check.finite(g + "/joints", values_of(c.joints));
  c.bones = r.read_int(g + "/bones");
  check.shape(g + "/bones", c.bones, -1, 2);
  check.indices(g + "/bones", values_of(c.bones), 0, nj, "joint");
  const long nb = c.bones.rows();
  if (r.has(g + "/leaf_tips")) {
    c.leaf_tips = r.read_double(g + "/leaf_tips");
    check.shape(g + "/leaf_tips", c.leaf_tips, nj, 3);
    check.finite(g + "/leaf_tips", values_of(c.leaf_tips));
  }

  const auto indptr = r.read_ints(g + "/weights/indptr");
  const auto indices = r.read_ints(g + "/weights/indices");
  const auto values = r.read_floats(g + "/weights/values");
  check.length(g + "/weights/indptr", indptr.size(), nv + 1);
  if (indptr.front() != 0) check.fail(g + "/weights/indptr", "does not start at 0");
  for (long v = 0; v < nv; ++v) {
    if (indptr[v + 1] < indptr[v]) {
      check.fail(g + "/weights/indptr", "decreases at row " + std::to_string(v));
    }
  }
  check.length(g + "/weights/indices", indices.size(), indptr.back());
  check.length(g + "/weights/values", values.size(), indptr.back());
  check.indices(g + "/weights/indices", indices, 0, nj, "joint");
  check.finite(g + "/weights/values", values);
  std::vector<Eigen::Triplet<double>> triplets;
  for (long v = 0; v < nv; ++v) {
    for (int k = indptr[v]; k < indptr[v + 1]; ++k) triplets.emplace_back(v, indices[k], values[k]);
  }
  c.weights.resize(nv, nj);
  c.weights.setFromTriplets(triplets.begin(), triplets.end());

  c.vertex_map = r.read_ints(g + "/vertex_map");
  check.indices(g + "/vertex_map", c.vertex_map, 0, nv, "vertex");
  const RowMatrixXd norm = r.read_double(g + "/normalisation");
  check.shape(g + "/normalisation", norm, 4, 4);
  check.finite(g + "/normalisation", values_of(norm));
  c.normalisation = norm;

  for (const auto& type : r.children(g + "/distances")) {
    const std::string dg = g + "/distances/" + type;
    DistanceData d;
    d.D = r.read_float(dg + "/D");
    check.shape(dg + "/D", d.D, nv, nb);
    check.finite(dg + "/D", values_of(d.D));
    d.topk_index = r.read_int(dg + "/topk_index");
    check.shape(dg + "/topk_index", d.topk_index, nv, -1);
    if (d.topk_index.cols() > nb) check.fail(dg + "/topk_index", "more candidates than bones");
    check.indices(dg + "/topk_index", values_of(d.topk_index), 0, nb, "bone");
    const long k = d.topk_index.cols();
    d.topk_distance = r.read_float(dg + "/topk_distance");
    check.shape(dg + "/topk_distance", d.topk_distance, nv, k);
    check.finite(dg + "/topk_distance", values_of(d.topk_distance));
    d.targets = r.read_float(dg + "/targets");
    check.shape(dg + "/targets", d.targets, nv, k);
    check.finite(dg + "/targets", values_of(d.targets));
    c.distances.emplace(type, std::move(d));
  }
  if (r.has(g + "/priors")) {
    for (const auto& type : r.children(g + "/priors")) {
      const std::string pg = g + "/priors/" + type;
      RowMatrixXf P = r.read_float(pg);
      check.shape(pg, P, nv, nb);
      check.finite(pg, values_of(P));
      if (P.size() > 0 && P.minCoeff() < 0) check.fail(pg, "has negative weights");
      c.priors.emplace(type, std::move(P));
    }
  }

  c.one_ring_edges = r.read_int(g + "/edges/one_ring");
  check.shape(g + "/edges/one_ring", c.one_ring_edges, -1, 2);
  check.indices(g + "/edges/one_ring", values_of(c.one_ring_edges), 0, nv, "vertex");
  c.geodesic_edges = r.read_int(g + "/edges/geodesic");
  check.shape(g + "/edges/geodesic", c.geodesic_edges, -1, 2);
  check.indices(g + "/edges/geodesic", values_of(c.geodesic_edges), 0, nv, "vertex");
  c.laplacian_indices = r.read_int(g + "/laplacian/indices");
  check.shape(g + "/laplacian/indices", c.laplacian_indices, -1, 2);
  check.indices(g + "/laplacian/indices", values_of(c.laplacian_indices), 0, nv, "vertex");
  c.laplacian_values = r.read_doubles(g + "/laplacian/values");
  check.length(g + "/laplacian/values", c.laplacian_values.size(),
               static_cast<std::size_t>(c.laplacian_indices.rows()));
  check.finite(g + "/laplacian/values", c.laplacian_values);

  c.source = r.read_attribute(g, "source");
  c.path = r.read_attribute(g, "path");
  c.licence = r.read_attribute(g, "licence");
  c.attribution = r.read_attribute(g, "attribution");
  c.skeleton = r.read_attribute(g, "skeleton");
  c.group = r.has_attribute(g, "group") ? r.read_attribute(g, "group") : c.name;
  if (r.has_attribute(g, "augmented_from")) {
    c.augmented_from = r.read_attribute(g, "augmented_from");
  }
  c.subdivision_levels = static_cast<int>(r.read_int_attribute(g, "subdivision_levels"));

  if (r.has(g + "/bind")) {
    std::vector<std::size_t> dims;
    c.bind = r.read_float_array(g + "/bind", dims);
    if (dims.size() != 2 || static_cast<long>(dims[0]) != nj || dims[1] != 12) {
      check.fail(g + "/bind", "expected " + std::to_string(nj) + "×12");
    }
    check.finite(g + "/bind", c.bind);
  }

  const std::string animations = g + "/animations";
  if (r.has(animations)) {
    std::vector<std::string> clips = r.children(animations);
    std::sort(clips.begin(), clips.end(), [](const std::string& a, const std::string& b) {
      return a.size() != b.size() ? a.size() < b.size() : a < b;  // numeric order of "0", "1", ..
    });
    for (const auto& clip : clips) {
      const std::string ag = animations + "/" + clip;
      AnimationData a;
      std::vector<std::size_t> dims;
      a.frames = r.read_float_array(ag + "/frames", dims);
      if (dims.size() != 3 || static_cast<long>(dims[1]) != nj || dims[2] != 12) {
        check.fail(ag + "/frames", "expected #frames×" + std::to_string(nj) + "×12");
      }
      check.finite(ag + "/frames", a.frames);
      a.num_frames = static_cast<int>(dims[0]);
      a.bind = r.read_float_array(ag + "/bind", dims);
      if (dims.size() != 2 || static_cast<long>(dims[0]) != nj || dims[1] != 12) {
        check.fail(ag + "/bind", "expected " + std::to_string(nj) + "×12");
      }
      a.name = r.read_attribute(ag, "name");
      a.fps = r.read_double_attribute(ag, "fps");
      c.animations.push_back(std::move(a));
    }
  }
  return c;
}

}  // namespace

void write_dataset(const std::filesystem::path& file, const Dataset& dataset, int deflate_level) {
  std::set<std::string> names;
  std::vector<std::string> name_list;
  for (const auto& c : dataset.characters) {
    check_name(file, c.name);
    check_transforms(file, c);
    if (!names.insert(c.name).second) {
      throw IoError(file.string() + ": duplicate character name '" + c.name + "'");
    }
    name_list.push_back(c.name);
  }
  const long n = static_cast<long>(dataset.characters.size());
  for (const auto& [split, s] : dataset.splits) {
    check_name(file, split);
    for (const auto* part : {&s.train, &s.val, &s.test}) {
      for (int i : *part) {
        if (i < 0 || i >= n) {
          throw IoError(file.string() + ": split '" + split + "' index " + std::to_string(i) +
                        " is not a character index (" + std::to_string(n) + " characters)");
        }
      }
    }
  }
  H5Writer w(file, deflate_level);
  w.write_attribute("/", "format_version", kFormatVersion);
  w.write_attribute("/", "skinlab_git_commit", dataset.git_commit);
  w.write_attribute("/", "preparation", dataset.preparation);
  w.write_strings("/character_names", name_list);
  w.create_group("/characters");
  for (const auto& c : dataset.characters) write_character(w, c);
  w.create_group("/splits");
  for (const auto& [split, s] : dataset.splits) {
    w.write("/splits/" + split + "/train", s.train);
    w.write("/splits/" + split + "/val", s.val);
    w.write("/splits/" + split + "/test", s.test);
  }
  std::vector<std::string> sources, paths, reasons;
  for (const auto& e : dataset.excluded) {
    sources.push_back(e.source);
    paths.push_back(e.path);
    reasons.push_back(e.reason);
  }
  w.write_strings("/excluded/source", sources);
  w.write_strings("/excluded/path", paths);
  w.write_strings("/excluded/reason", reasons);
  w.commit();
}

geometry::Skeleton PreparedCharacter::rig() const {
  geometry::Skeleton s;
  s.names = joint_names;
  s.parents = parents;
  s.positions = joints;
  s.leaf_tips = leaf_tips;
  s.validate(name);
  const auto list = s.bones();
  bool same = static_cast<Eigen::Index>(list.size()) == bones.rows();
  for (std::size_t b = 0; same && b < list.size(); ++b) {
    const auto i = static_cast<Eigen::Index>(b);
    same = list[b].start == bones(i, 0) && list[b].end == bones(i, 1);
  }
  if (!same) {
    throw IoError(name + ": the stored bones are not the skeleton's bones in RigNet's order "
                  "(Skeleton::bones()); re-prepare the dataset with this build");
  }
  return s;
}

geometry::Mesh PreparedCharacter::mesh() const {
  geometry::Mesh m;
  m.V = V;
  m.F = F;
  return m;
}

const std::vector<float>* PreparedCharacter::bind_pose() const {
  if (!bind.empty()) return &bind;
  if (!animations.empty()) return &animations.front().bind;
  return nullptr;
}

Eigen::Isometry3d joint_transform(const float* m) {
  Eigen::Matrix3d r;
  Eigen::Vector3d t;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = m[4 * i + j];
    t(i) = m[4 * i + 3];
  }
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = Eigen::Quaterniond(r).normalized().toRotationMatrix();
  out.translation() = t;
  return out;
}

std::unique_ptr<H5Reader> open_dataset_file(const std::filesystem::path& file) {
  const std::string advice = "written by an older skinlab: re-run `skinlab prepare` with this build";
  auto r = std::make_unique<H5Reader>(file, advice);
  if (!r->has_attribute("/", "format_version")) {
    throw IoError(file.string() + ": not a skinlab dataset (no root attribute 'format_version')");
  }
  const std::int64_t version = r->read_int_attribute("/", "format_version");
  if (version >= 1 && version < kFormatVersion) {
    throw IoError(file.string() + ": written by an older skinlab (format_version " +
                  std::to_string(version) + "; this build reads version " +
                  std::to_string(kFormatVersion) +
                  ", whose strings are fixed-length): re-run `skinlab prepare` on its dataset "
                  "config to write it again");
  }
  if (version != kFormatVersion) {
    throw IoError(file.string() + ": format_version " + std::to_string(version) +
                  " is not supported (this build reads version " +
                  std::to_string(kFormatVersion) + ")");
  }
  return r;
}

Dataset read_dataset(const std::filesystem::path& file) {
  const std::unique_ptr<H5Reader> reader = open_dataset_file(file);
  const H5Reader& r = *reader;
  Dataset d;
  d.git_commit = r.read_attribute("/", "skinlab_git_commit");
  d.preparation = r.read_attribute("/", "preparation");
  const auto names = r.read_strings("/character_names");
  for (const auto& name : names) d.characters.push_back(read_character(r, name));
  const Checker check(r);
  const long n = static_cast<long>(names.size());
  if (r.has("/splits")) {
    for (const auto& split : r.children("/splits")) {
      Split s;
      const std::string sg = "/splits/" + split;
      s.train = r.read_ints(sg + "/train");
      s.val = r.read_ints(sg + "/val");
      s.test = r.read_ints(sg + "/test");
      check.indices(sg + "/train", s.train, 0, n, "character");
      check.indices(sg + "/val", s.val, 0, n, "character");
      check.indices(sg + "/test", s.test, 0, n, "character");
      d.splits.emplace(split, std::move(s));
    }
  }
  const auto sources = r.read_strings("/excluded/source");
  const auto paths = r.read_strings("/excluded/path");
  const auto reasons = r.read_strings("/excluded/reason");
  check.length("/excluded/path", paths.size(), sources.size());
  check.length("/excluded/reason", reasons.size(), sources.size());
  for (std::size_t i = 0; i < sources.size(); ++i) {
    d.excluded.push_back({sources[i], paths[i], reasons[i]});
  }
  return d;
}

std::map<std::string, std::string> read_character_units(const std::filesystem::path& file,
                                                        const std::string& per) {
  if (per != "family" && per != "group") {
    throw ConfigError("units of `" + file.string() + "`: unknown unit '" + per +
                      "'; choose family or group");
  }
  const std::unique_ptr<H5Reader> reader = open_dataset_file(file);
  const H5Reader& r = *reader;
  const Checker check(r);
  const std::string attribute = per == "family" ? "skeleton" : "group";
  std::map<std::string, std::string> units;
  for (const auto& name : r.read_strings("/character_names")) {
    const std::string g = group_of(name);
    if (!r.has(g)) check.fail(g, "character listed in /character_names has no group");
    // A file without `group` treats every character as its own group (read_character).
    const std::string unit =
        per == "group" && !r.has_attribute(g, "group") ? name : r.read_attribute(g, attribute);
    units[name] = r.read_attribute(g, "source") + "/" + unit;
  }
  return units;
}

}  // namespace skinlab::data

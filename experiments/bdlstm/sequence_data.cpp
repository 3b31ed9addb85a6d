#include "experiments/bdlstm/sequence_data.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "framework/core/error.hpp"
#include "framework/tensors/tensors.hpp"
#include "framework/geometry/lbs.hpp"
#include "framework/geometry/normalize.hpp"
#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/one_ring.hpp"

namespace skinlab::bdlstm {

namespace fs = std::filesystem;

SequenceOptions SequenceOptions::from(const config::Node& node, std::vector<std::string> other_keys) {
  SequenceOptions o;
  if (!node.exists() || node.is_null()) return o;
  config::Fields f(node, "sequences", std::move(other_keys));
  f.optional("characters", o.characters);
  f.optional("frame_stride", o.frame_stride).check(o.frame_stride >= 1, "frame_stride", "must be ≥ 1");
  f.optional("min_frames", o.min_frames).check(o.min_frames >= 2, "min_frames", "must be ≥ 2");
  f.optional("test_fraction", o.test_fraction)
      .check(o.test_fraction > 0 && o.test_fraction < 1, "test_fraction", "must be in (0, 1)");
  f.optional("val_fraction", o.val_fraction)
      .check(std::isfinite(o.val_fraction) && o.val_fraction >= 0, "val_fraction",
             "must be ≥ 0 (0: no validation window)");
  f.check(o.val_fraction + o.test_fraction < 1, "val_fraction",
          fmt::format("val_fraction + test_fraction = {} + {} must be < 1 (the rest of each "
                      "sequence is for training)",
                      o.val_fraction, o.test_fraction));
  std::int64_t seed = 0;
  f.optional("seed", seed).check(seed >= 0, "seed", "must be ≥ 0");
  o.seed = static_cast<std::uint64_t>(seed);
  f.optional("folder", o.folder);
  std::vector<double> up{0, 1, 0};
  f.optional("up", up).check(up.size() == 3 && Eigen::Vector3d(up[0], up[1], up.back()).norm() > 0 &&
                                 std::all_of(up.begin(), up.end(), [](double x) { return std::isfinite(x); }),
                             "up", "must be a non-zero 3-vector, e.g. [0, 0, 1]");
  o.up = Eigen::Vector3d(up[0], up[1], up[2]);
  f.finish();
  return o;
}

std::pair<int, int> held_out_window(int frames, double fraction, std::uint64_t seed,
                                    const std::string& key) {
  if (frames < 2) return {frames, frames};
  const int length = std::clamp(static_cast<int>(std::lround(fraction * frames)), 1, frames - 1);
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a
  for (unsigned char ch : key) {
    h ^= ch;
    h *= 1099511628211ULL;
  }
  std::uint64_t z = h + seed + 0x9e3779b97f4a7c15ULL;  // splitmix64
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  const int begin = static_cast<int>(z % static_cast<std::uint64_t>(frames - length + 1));
  return {begin, begin + length};
}

namespace {

/// The validation window's length in a sequence of `frames` frames: round(fraction · frames),
/// at least 1 (fraction > 0).
int validation_length(int frames, double fraction) {
  return std::max(1, static_cast<int>(std::lround(fraction * frames)));
}

}  // namespace

std::optional<std::pair<int, int>> validation_window(int frames, std::pair<int, int> test,
                                                     double fraction) {
  if (fraction <= 0) return std::pair{0, 0};
  const int length = validation_length(frames, fraction);
  if ((test.second - test.first) + length > frames - 1) return std::nullopt;
  if (test.first >= length) return std::pair{test.first - length, test.first};
  if (test.second + length <= frames) return std::pair{test.second, test.second + length};
  return std::nullopt;
}

SequenceData::SequenceData(const data::Dataset& dataset, const std::string& file,
                           const SequenceOptions& options)
    : options_(options), source_(file) {
  std::vector<int> selected;
  if (options.characters.empty()) {
    for (std::size_t i = 0; i < dataset.characters.size(); ++i) selected.push_back(static_cast<int>(i));
  } else {
    for (const std::string& name : options.characters) {
      const auto it = std::find_if(dataset.characters.begin(), dataset.characters.end(),
                                   [&](const data::PreparedCharacter& c) { return c.name == name; });
      if (it == dataset.characters.end()) {
        throw IoError(fmt::format("{}: no character '{}' (sequences.characters)", file, name));
      }
      selected.push_back(static_cast<int>(it - dataset.characters.begin()));
    }
  }

  for (int index : selected) {
    const data::PreparedCharacter& c = dataset.characters[static_cast<std::size_t>(index)];
    if (c.animations.empty()) {
      excluded_.push_back(c.name + ": no animation clip");
      continue;
    }
    SequenceCharacter out;
    out.name = c.name;
    out.dataset_index = index;
    out.rest = geometry::Mesh{c.V, c.F};
    out.acap = std::make_shared<const geometry::AcapEncoder>(out.rest, file + ": " + c.name);
    out.one_ring = data::to_long(c.one_ring_edges);
    const auto J = static_cast<std::size_t>(c.num_joints());
    for (const data::AnimationData& a : c.animations) {
      if (a.bind.size() != J * 12 || a.frames.size() != static_cast<std::size_t>(a.num_frames) * J * 12) {
        throw IoError(fmt::format("{}: clip '{}' of character '{}' does not have its {} joints",
                                  file, a.name, c.name, J));
      }
      std::vector<Eigen::Isometry3d> bind_inverse;
      for (std::size_t j = 0; j < J; ++j) {
        bind_inverse.push_back(data::joint_transform(a.bind.data() + 12 * j).inverse());
      }
      MeshSequence s;
      s.clip = a.name;
      s.fps = a.fps / options.frame_stride;
      for (int f = 0; f < a.num_frames; f += options.frame_stride) {
        std::vector<Eigen::Affine3d> pose;
        for (std::size_t j = 0; j < J; ++j) {
          const float* m = a.frames.data() + (static_cast<std::size_t>(f) * J + j) * 12;
          pose.emplace_back((data::joint_transform(m) * bind_inverse[j]).matrix());
        }
        s.positions.push_back(geometry::lbs(out.rest.V, c.weights, pose));
      }
      add_sequence(out, std::move(s));
    }
    add_character(std::move(out), "no clip with at least min_frames sampled frames and room for its "
                                  "held-out windows");
  }
  finish();
}

namespace {

/// File names in natural order: runs of digits compare by value ("frame2" < "frame10").
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      std::string da = a.substr(i, ie - i), db = b.substr(j, je - j);
      da.erase(0, std::min(da.find_first_not_of('0'), da.size()));
      db.erase(0, std::min(db.find_first_not_of('0'), db.size()));
      if (da.size() != db.size()) return da.size() < db.size();
      if (da != db) return da < db;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

/// The sub-directories (or, with `ext`, the regular files of that extension) of `dir`, sorted.
std::vector<fs::path> entries(const fs::path& dir, const std::string& ext = "") {
  std::vector<fs::path> out;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    if (ext.empty() ? e.is_directory() : e.is_regular_file() && e.path().extension() == ext) {
      out.push_back(e.path());
    }
  }
  std::sort(out.begin(), out.end(), [](const fs::path& a, const fs::path& b) {
    return natural_less(a.filename().string(), b.filename().string());
  });
  return out;
}

/// A frame of a folder sequence, checked against the template (`file` named in errors).
Eigen::MatrixXd read_frame(const fs::path& file, const geometry::Mesh& rest, const fs::path& rest_file) {
  const geometry::Mesh m = geometry::read_obj(file);
  if (m.num_vertices() != rest.num_vertices()) {
    throw IoError(fmt::format("{}: {} vertices, but the template {} has {} (every frame of a "
                              "sequence needs the template's vertices, in its order)",
                              file.string(), m.num_vertices(), rest_file.string(), rest.num_vertices()));
  }
  if (m.F.rows() != rest.F.rows()) {
    throw IoError(fmt::format("{}: {} faces, but the template {} has {}", file.string(), m.F.rows(),
                              rest_file.string(), rest.F.rows()));
  }
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    if (m.F.row(f) != rest.F.row(f)) {
      throw IoError(fmt::format("{}: face {} is ({}, {}, {}), the template's is ({}, {}, {}) "
                                "(a sequence has fixed connectivity)",
                                file.string(), f, m.F(f, 0), m.F(f, 1), m.F(f, 2), rest.F(f, 0),
                                rest.F(f, 1), rest.F(f, 2)));
    }
  }
  return m.V;
}

}  // namespace

SequenceData::SequenceData(const SequenceOptions& options) : options_(options), source_(options.folder) {
  const fs::path root(options.folder);
  if (options.folder.empty() || !fs::is_directory(root)) {
    throw IoError(fmt::format("{}: not a directory (sequences.folder)", options.folder));
  }
  std::vector<fs::path> selected;
  if (options.characters.empty()) {
    selected = entries(root);
  } else {
    for (const std::string& name : options.characters) {
      if (!fs::is_directory(root / name)) {
        throw IoError(fmt::format("{}: no character folder '{}' (sequences.characters)", root.string(), name));
      }
      selected.push_back(root / name);
    }
  }
  for (const fs::path& dir : selected) {
    const std::string name = dir.filename().string();
    std::vector<std::pair<fs::path, std::vector<fs::path>>> clips;  // clip folder, its frames
    for (const fs::path& clip : entries(dir)) clips.emplace_back(clip, entries(clip, ".obj"));
    fs::path rest_file = dir / "template.obj";
    if (!fs::exists(rest_file)) {
      const auto first = std::find_if(clips.begin(), clips.end(),
                                      [](const auto& clip) { return !clip.second.empty(); });
      if (first == clips.end()) {
        excluded_.push_back(name + ": no clip folder with .obj frames");
        continue;
      }
      rest_file = first->second.front();
    }
    geometry::Character rest;
    rest.name = name;
    rest.mesh = geometry::read_obj(rest_file);
    const geometry::Similarity to_metres = geometry::normalize(rest, {options.up, 1.0});
    SequenceCharacter out;
    out.name = name;
    out.dataset_index = static_cast<int>(characters_.size());
    out.rest = rest.mesh;
    out.acap = std::make_shared<const geometry::AcapEncoder>(out.rest, rest_file.string());
    out.one_ring = data::to_long(data::RowMatrixXi(geometry::one_ring(out.rest).edges.transpose()));
    for (const auto& [clip, files] : clips) {
      MeshSequence s;
      s.clip = clip.filename().string();
      for (std::size_t f = 0; f < files.size(); f += static_cast<std::size_t>(options.frame_stride)) {
        s.positions.push_back(to_metres.apply(read_frame(files[f], rest.mesh, rest_file)));
      }
      add_sequence(out, std::move(s));
    }
    add_character(std::move(out), "no clip with at least min_frames frames and room for its held-out "
                                  "windows");
  }
  finish();
}

void SequenceData::add_sequence(SequenceCharacter& out, MeshSequence s) {
  if (s.num_frames() < options_.min_frames) {
    excluded_.push_back(fmt::format("{}/{}: {} sampled frames, fewer than min_frames = {}", out.name,
                                    s.clip, s.num_frames(), options_.min_frames));
    return;
  }
  const std::pair<int, int> test =
      held_out_window(s.num_frames(), options_.test_fraction, options_.seed, out.name + "/" + s.clip);
  const std::optional<std::pair<int, int>> val =
      validation_window(s.num_frames(), test, options_.val_fraction);
  if (!val) {
    excluded_.push_back(fmt::format(
        "{}/{}: {} sampled frames, no room for a validation window of {} frame(s) (val_fraction = "
        "{}) beside its test window {}..{} (test_fraction = {}) with a training frame left",
        out.name, s.clip, s.num_frames(),
        validation_length(s.num_frames(), options_.val_fraction),
        options_.val_fraction, test.first, test.second - 1, options_.test_fraction));
    return;
  }
  std::tie(s.test_begin, s.test_end) = test;
  std::tie(s.val_begin, s.val_end) = *val;
  s.features = out.acap->encode_sequence(s.positions);
  out.sequences.push_back(std::move(s));
}

void SequenceData::add_character(SequenceCharacter out, const std::string& why_empty) {
  if (out.sequences.empty()) {
    excluded_.push_back(out.name + ": " + why_empty);
    return;
  }
  characters_.push_back(std::move(out));
}

void SequenceData::finish() {
  for (const std::string& e : excluded_) spdlog::info("sequences: left out {}", e);
  if (characters_.empty()) {
    throw IoError(fmt::format("{}: no character with a clip of at least {} sampled frames and room "
                              "for its held-out windows",
                              source_, options_.min_frames));
  }
}

}  // namespace skinlab::bdlstm

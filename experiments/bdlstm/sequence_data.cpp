#include "experiments/bdlstm/sequence_data.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "framework/core/error.hpp"
#include "framework/data/tensors.hpp"
#include "framework/geometry/lbs.hpp"

namespace skinlab::bdlstm {

SequenceOptions SequenceOptions::from(const config::Node& node, std::vector<std::string> other_keys) {
  SequenceOptions o;
  if (!node.exists() || node.is_null()) return o;
  config::Fields f(node, "sequences", std::move(other_keys));
  f.optional("characters", o.characters);
  f.optional("frame_stride", o.frame_stride).check(o.frame_stride >= 1, "frame_stride", "must be ≥ 1");
  f.optional("min_frames", o.min_frames).check(o.min_frames >= 2, "min_frames", "must be ≥ 2");
  f.optional("test_fraction", o.test_fraction)
      .check(o.test_fraction > 0 && o.test_fraction < 1, "test_fraction", "must be in (0, 1)");
  std::int64_t seed = 0;
  f.optional("seed", seed).check(seed >= 0, "seed", "must be ≥ 0");
  o.seed = static_cast<std::uint64_t>(seed);
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

SequenceData::SequenceData(const data::Dataset& dataset, const std::string& file,
                           const SequenceOptions& options)
    : options_(options) {
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
      const int sampled = (a.num_frames + options.frame_stride - 1) / options.frame_stride;
      if (sampled < options.min_frames) {
        excluded_.push_back(fmt::format("{}/{}: {} sampled frames, fewer than min_frames = {}",
                                        c.name, a.name, sampled, options.min_frames));
        continue;
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
      s.features = out.acap->encode_sequence(s.positions);
      std::tie(s.test_begin, s.test_end) = held_out_window(
          s.num_frames(), options.test_fraction, options.seed, c.name + "/" + a.name);
      out.sequences.push_back(std::move(s));
    }
    if (out.sequences.empty()) {
      excluded_.push_back(c.name + ": no clip with at least min_frames sampled frames");
      continue;
    }
    characters_.push_back(std::move(out));
  }
  for (const std::string& e : excluded_) spdlog::info("sequences: left out {}", e);
  if (characters_.empty()) {
    throw IoError(fmt::format("{}: no character with a clip of at least {} sampled frames", file,
                              options.min_frames));
  }
}

}  // namespace skinlab::bdlstm

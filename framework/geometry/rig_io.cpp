#include "framework/geometry/rig_io.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/geometry/obj_io.hpp"
#include "framework/geometry/text_parsing.hpp"

namespace skinlab::geometry {

Rig read_rig(const std::filesystem::path& file, int num_vertices, const WeightCheck& check,
             SkinLines skin) {
  const std::string text = read_file(file);
  std::vector<std::string> names;
  std::vector<double> coords;
  std::unordered_map<std::string, int> index;
  std::vector<std::string> parent_names;
  std::vector<int> parent_line;
  std::string root;
  int root_line = 0;
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<int> skin_line(num_vertices, 0);
  bool any_skin = false;
  std::string ignored_skin;

  auto joint = [&](std::string_view name, const LineContext& at) {
    auto it = index.find(std::string(name));
    if (it == index.end()) at.fail("unknown joint '" + std::string(name) + "'");
    return it->second;
  };
  // Runs `read` over the skin lines' data; under SkinLines::ignore_mismatch its first error is
  // kept (and the later skin lines skipped) instead of thrown.
  auto skin_part = [&](const std::function<void()>& read) {
    if (!ignored_skin.empty()) return;
    try {
      read();
    } catch (const GeometryError& e) {
      if (skin == SkinLines::require) throw;
      ignored_skin = e.what();
      entries.clear();
    }
  };

  for_each_line(text, file, [&](const std::vector<std::string_view>& w, const LineContext& at) {
    if (w[0] == "joints") {
      if (w.size() != 5) at.fail("expected 'joints NAME x y z'");
      const std::string name(w[1]);
      if (!index.emplace(name, static_cast<int>(names.size())).second) {
        at.fail("duplicate joint '" + name + "'");
      }
      names.push_back(name);
      for (int k = 2; k <= 4; ++k) coords.push_back(at.number<double>(w[k], "coordinate"));
      parent_names.emplace_back();
      parent_line.push_back(0);
    } else if (w[0] == "root") {
      if (w.size() != 2) at.fail("expected 'root NAME'");
      if (!root.empty()) at.fail("second root line (first on line " + std::to_string(root_line) + ")");
      joint(w[1], at);
      root = std::string(w[1]);
      root_line = at.line;
    } else if (w[0] == "hier") {
      if (w.size() != 3) at.fail("expected 'hier PARENT CHILD'");
      joint(w[1], at);
      const int child = joint(w[2], at);
      if (!parent_names[child].empty()) {
        at.fail("joint '" + names[child] + "' already has parent '" + parent_names[child] +
                "' (line " + std::to_string(parent_line[child]) + ")");
      }
      parent_names[child] = std::string(w[1]);
      parent_line[child] = at.line;
    } else if (w[0] == "skin") {
      skin_part([&] {
        if (w.size() < 4 || w.size() % 2 != 0) at.fail("expected 'skin VID JOINT WEIGHT [JOINT WEIGHT ...]'");
        const long vid = at.number<long>(w[1], "vertex id");
        if (vid < 0 || vid >= num_vertices) {
          at.fail("vertex " + std::to_string(vid) + " is out of range (the mesh has " +
                  std::to_string(num_vertices) + " vertices)");
        }
        if (skin_line[vid] != 0) {
          at.fail("vertex " + std::to_string(vid) + " already has weights (line " +
                  std::to_string(skin_line[vid]) + ")");
        }
        skin_line[vid] = at.line;
        any_skin = true;
        for (std::size_t k = 2; k < w.size(); k += 2) {
          const int j = joint(w[k], at);
          entries.emplace_back(static_cast<int>(vid), j, at.number<double>(w[k + 1], "weight"));
        }
      });
    } else {
      at.fail("unknown statement '" + std::string(w[0]) + "' (expected joints, root, hier or skin)");
    }
  });

  const std::string source = file.string();
  if (names.empty()) throw GeometryError(source + ": no 'joints' lines");
  if (root.empty()) throw GeometryError(source + ": no 'root' line");
  if (!parent_names[index.at(root)].empty()) {
    throw GeometryError(source + ":" + std::to_string(root_line) + ": root '" + root +
                        "' has a parent ('" + parent_names[index.at(root)] + "', line " +
                        std::to_string(parent_line[index.at(root)]) + ")");
  }
  for (std::size_t j = 0; j < names.size(); ++j) {
    if (parent_names[j].empty() && names[j] != root) {
      throw GeometryError(source + ": joint '" + names[j] + "' has no 'hier' line and is not the root '" + root + "'");
    }
  }
  Rig rig;
  rig.skeleton = Skeleton::from_parent_names(
      names,
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
          coords.data(), static_cast<Eigen::Index>(names.size()), 3),
      parent_names, source);
  if (any_skin) {
    skin_part([&] {
      SparseWeights weights(num_vertices, rig.skeleton.num_joints());
      // Duplicate joints within one line would be summed by setFromTriplets; reject them instead.
      weights.setFromTriplets(entries.begin(), entries.end(), [&](double, double) -> double {
        throw GeometryError(source + ": a skin line names the same joint twice");
      });
      check_weights(weights, num_vertices, rig.skeleton, source, check);
      rig.weights = std::move(weights);
    });
  }
  if (!ignored_skin.empty()) {
    // The message names the file already (and the line, where there is one).
    spdlog::warn("{}; its skin lines do not fit this mesh and are ignored (skeleton only)",
                 ignored_skin);
    rig.ignored_skin = std::move(ignored_skin);
  }
  return rig;
}

void write_rig(const std::filesystem::path& file, const Skeleton& skeleton,
               const SparseWeights& weights) {
  for (const auto& name : skeleton.names) {
    if (name.empty() || name.find_first_of(" \t\r\n#") != std::string::npos) {
      throw GeometryError(file.string() + ": joint name '" + name +
                          "' cannot be written to a rig file (empty, whitespace or '#')");
    }
  }
  std::string out;
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    out += fmt::format("joints {} {} {} {}\n", skeleton.names[j], skeleton.positions(j, 0),
                       skeleton.positions(j, 1), skeleton.positions(j, 2));
  }
  out += "root " + skeleton.names[skeleton.root()] + "\n";
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    if (skeleton.parents[j] >= 0) out += "hier " + skeleton.names[skeleton.parents[j]] + " " + skeleton.names[j] + "\n";
  }
  for (Eigen::Index v = 0; v < weights.outerSize(); ++v) {
    out += fmt::format("skin {}", v);
    for (SparseWeights::InnerIterator it(weights, v); it; ++it) {
      out += fmt::format(" {} {}", skeleton.names[it.col()], it.value());
    }
    out += "\n";
  }
  write_file_atomic(file, out);
}

Character read_obj_rig(const std::filesystem::path& obj, const std::filesystem::path& rig_file,
                       const WeightCheck& check, SkinLines skin) {
  Character character;
  character.name = obj.stem().string();
  character.mesh = read_obj(obj);
  Rig rig = read_rig(rig_file, character.mesh.num_vertices(), check, skin);
  character.skeleton = std::move(rig.skeleton);
  character.weights = std::move(rig.weights);
  return character;
}

}  // namespace skinlab::geometry

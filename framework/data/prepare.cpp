#include "framework/data/prepare.hpp"

#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <mutex>
#include <optional>
#include <set>

#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/progress.hpp"
#include "framework/core/registry.hpp"

namespace skinlab::data {

namespace fs = std::filesystem;

namespace {

std::vector<config::Node> plugin_list(const config::Node& node, const std::string& what,
                                      bool allow_empty) {
  if (!node.is_sequence() || (!allow_empty && node.size() == 0)) {
    node.fail("expected a " + std::string(allow_empty ? "" : "non-empty ") + "list of " + what +
              " nodes ({type: <key>, ...})");
  }
  std::vector<config::Node> out;
  for (std::size_t i = 0; i < node.size(); ++i) out.push_back(node[i]);
  return out;
}

std::vector<NamedDistance> make_distances(const std::vector<config::Node>& nodes) {
  std::vector<NamedDistance> out;
  std::set<std::string> types;
  for (const auto& node : nodes) {
    NamedDistance d;
    d.type = node.required_type("distance");
    if (!types.insert(d.type).second) {
      node.fail("distance type '" + d.type + "' is listed twice (one entry per type)");
    }
    d.distance = distance_registry().create(node);
    out.push_back(std::move(d));
  }
  return out;
}

/// `text` with every line indented by two spaces and ending in a newline (a YAML block).
std::string indent(const std::string& text) {
  std::string out;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    if (end > start) out += "  " + text.substr(start, end - start) + "\n";
    start = end + 1;
  }
  return out;
}

std::string git_commit() {
  const GitState git = git_state(source_dir());
  return git.commit + (git.dirty ? "-dirty" : "");
}

/// The character stored in a partial file, when it is complete and made with `preparation`.
std::optional<PreparedCharacter> reusable(const fs::path& file, const std::string& name,
                                          const std::string& preparation) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return std::nullopt;
  try {
    Dataset d = read_dataset(file);
    if (d.preparation != preparation || d.characters.size() != 1 || d.characters[0].name != name) {
      spdlog::info("{}: made with another configuration; recomputing", file.string());
      return std::nullopt;
    }
    return std::move(d.characters[0]);
  } catch (const Error& e) {
    spdlog::warn("{}; recomputing", e.what());
    return std::nullopt;
  }
}

}  // namespace

PrepareConfig PrepareConfig::from(const config::Config& config) {
  PrepareConfig c;
  config::Fields f(config.root(), "dataset config", {});
  c.sources = plugin_list(f.section("sources"), "dataset", false);
  c.cleaning = CleaningOptions::from(f.section("cleaning"));
  c.splits = SplitOptions::from(f.section("splits"));
  const config::Node preprocess = f.section("preprocess");
  c.preprocess = PreprocessOptions::from(preprocess);
  const config::Node distances = f.section("distances");
  c.distances = plugin_list(distances, "distance", false);
  std::string output;
  f.required("output", output);
  f.check(!output.empty(), "output", "must not be empty");
  f.finish();
  c.output = output;
  for (const auto& node : c.sources) dataset_registry().create(node);  // validates options
  make_distances(c.distances);
  c.preparation = "preprocess:\n" + indent(preprocess.exists() ? preprocess.to_yaml() : "{}") +
                  "distances:\n" + indent(distances.to_yaml());
  return c;
}

PrepareReport prepare_dataset(const PrepareConfig& config, const PrepareOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  PrepareReport report;
  report.output = config.output;

  std::vector<datasets::SourceCharacter> read_all;
  for (const auto& node : config.sources) {
    const auto builder = dataset_registry().create(node);
    auto read = builder->read(report.excluded);
    spdlog::info("source {}: {} characters", node.required_type("dataset"), read.size());
    for (auto& c : read) read_all.push_back(std::move(c));
  }
  {
    std::set<std::string> names;
    for (const auto& c : read_all) {
      if (!names.insert(c.character.name).second) {
        throw Error("two sources give a character named '" + c.character.name +
                    "' (the second from " + c.source + ": " + c.path + ")");
      }
    }
  }
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  std::vector<datasets::SourceCharacter> characters;
  std::vector<std::string> groups;
  std::vector<CleanedCharacter> cleaned;
  arena.execute([&] { cleaned = clean(std::move(read_all), config.cleaning, report.excluded); });
  for (auto& c : cleaned) {
    characters.push_back(std::move(c.source));
    groups.push_back(std::move(c.group));
  }
  const std::vector<NamedDistance> distances = make_distances(config.distances);

  const fs::path partial = fs::path(config.output.string() + ".partial");
  if (!config.output.parent_path().empty()) fs::create_directories(config.output.parent_path());
  fs::create_directories(partial);
  const std::string commit = git_commit();

  const std::size_t n = characters.size();
  const bool sharded = options.shard_count > 1;
  if (sharded && (options.shard_index < 0 || options.shard_index >= options.shard_count)) {
    throw Error("prepare: shard " + std::to_string(options.shard_index) + " of " +
                std::to_string(options.shard_count) + " does not exist");
  }
  const auto mine = [&](std::size_t i) {
    return !sharded || i % static_cast<std::size_t>(options.shard_count) ==
                           static_cast<std::size_t>(options.shard_index);
  };
  std::vector<std::optional<std::string>> failure(n);
  std::vector<char> reused(n, 0);
  std::mutex mutex;
  std::optional<Progress> progress;
  std::size_t share = 0;
  for (std::size_t i = 0; i < n; ++i) share += mine(i) ? 1 : 0;
  if (options.progress) progress.emplace("prepare", share);

  auto work = [&](std::size_t i) {
    if (!mine(i)) return;
    const auto& source = characters[i];
    const std::string& name = source.character.name;
    const fs::path file = partial / (name + ".h5");
    try {
      if (reusable(file, name, config.preparation)) {
        reused[i] = 1;
      } else {
        Dataset one;
        one.git_commit = commit;
        one.preparation = config.preparation;
        one.characters.push_back(preprocess(source, distances, config.preprocess));
        write_dataset(file, one, 0);  // uncompressed: HDF5's global lock would serialise deflate
      }
    } catch (const std::exception& e) {
      const std::string what = e.what();
      failure[i] = what.find(name) == std::string::npos ? name + ": " + what : what;
    }
    std::lock_guard<std::mutex> lock(mutex);
    if (progress) progress->tick();
  };
  arena.execute([&] { tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) { work(i); }); });
  if (progress) progress->finish();
  if (sharded) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!mine(i)) continue;
      if (failure[i]) {
        report.excluded.push_back({characters[i].source, characters[i].path, *failure[i]});
      } else {
        (reused[i] ? report.reused : report.computed) += 1;
      }
    }
    report.characters = report.computed + report.reused;
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    spdlog::info("shard {} of {}: {} characters into {} ({} computed, {} reused), {} failed, {:.2f} s",
                 options.shard_index, options.shard_count, report.characters, partial.string(),
                 report.computed, report.reused, share - report.characters, report.seconds);
    return report;
  }

  Dataset dataset;
  dataset.git_commit = commit;
  dataset.preparation = config.preparation;
  dataset.excluded = report.excluded;
  for (std::size_t i = 0; i < n; ++i) {
    if (failure[i]) {
      dataset.excluded.push_back({characters[i].source, characters[i].path, *failure[i]});
      spdlog::warn("excluded {}", *failure[i]);
      continue;
    }
    Dataset one = read_dataset(partial / (characters[i].character.name + ".h5"));
    dataset.characters.push_back(std::move(one.characters.at(0)));
    dataset.characters.back().group = groups[i];
    (reused[i] ? report.reused : report.computed) += 1;
  }
  {
    std::vector<std::string> group, skeleton, source;
    for (const auto& c : dataset.characters) {
      group.push_back(c.group);
      skeleton.push_back(c.skeleton);
      source.push_back(c.source);
    }
    dataset.splits = make_splits(group, skeleton, source, config.splits);
    for (const auto& [name, split] : dataset.splits) {
      spdlog::info("split {}: {} train, {} val, {} test", name, split.train.size(),
                   split.val.size(), split.test.size());
    }
  }
  write_dataset(config.output, dataset);
  report.characters = dataset.characters.size();
  report.excluded = dataset.excluded;
  if (!options.keep_partial) {
    std::error_code ec;
    fs::remove_all(partial, ec);
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("prepared {}: {} characters ({} computed, {} reused), {} excluded, {:.2f} s",
               config.output.string(), report.characters, report.computed, report.reused,
               report.excluded.size(), report.seconds);
  return report;
}

}  // namespace skinlab::data

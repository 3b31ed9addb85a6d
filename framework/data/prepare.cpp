#include "framework/data/prepare.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <mutex>
#include <optional>
#include <set>

#include "framework/binders/binder.hpp"
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
  const GitState& git = build_git_state();
  return git.commit + (git.dirty ? "-dirty-" + git.diff_sha256.substr(0, 12) : "");
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

/// One character to preprocess: characters[source] itself (copy -1) or its augmented copy.
struct Job {
  std::size_t source = 0;
  int copy = -1;
  std::string name;  ///< the prepared character's name (and its partial file's stem)
};

struct JobResult {
  bool reused = false;
  std::optional<std::string> failure;
};

void add_copies(std::vector<Job>& jobs, std::size_t source, const std::string& name, int copies) {
  for (int c = 0; c < copies; ++c) jobs.push_back({source, c, augmented_name(name, c)});
}

/// Per character index: whether the train part of some split holds it.
std::vector<bool> trained_in_some_split(const std::map<std::string, Split>& splits,
                                        std::size_t count) {
  std::vector<bool> out(count, false);
  for (const auto& [name, split] : splits) {
    for (int i : split.train) out.at(static_cast<std::size_t>(i)) = true;
  }
  return out;
}

/// Throws when a copy's name would be a source character's name.
void check_copy_names(const std::vector<datasets::SourceCharacter>& characters, int copies) {
  std::set<std::string> names;
  for (const auto& c : characters) names.insert(c.character.name);
  for (const auto& c : characters) {
    for (int k = 0; k < copies; ++k) {
      const std::string copy = augmented_name(c.character.name, k);
      if (names.count(copy)) {
        throw Error("preprocess.augment: the copy '" + copy + "' of '" + c.character.name +
                    "' would have the name of a source character");
      }
    }
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
  for (const auto& node : c.preprocess.priors) binder_registry().create(node);  // validates
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
  const int copies = config.preprocess.augment.copies;
  if (copies > 0) check_copy_names(characters, copies);

  // Preprocesses `jobs` into their partial files (or finds them done), in parallel.
  const auto run = [&](const std::vector<Job>& jobs, const std::string& label) {
    std::vector<JobResult> results(jobs.size());
    std::mutex mutex;
    std::optional<Progress> progress;
    if (options.progress && !jobs.empty()) progress.emplace(label, jobs.size());
    auto work = [&](std::size_t k) {
      const Job& job = jobs[k];
      const auto& source = characters[job.source];
      const fs::path file = partial / (job.name + ".h5");
      try {
        if (reusable(file, job.name, config.preparation)) {
          results[k].reused = true;
        } else {
          PreprocessMode mode;
          mode.augment_copy = job.copy;
          Dataset one;
          one.git_commit = commit;
          one.preparation = config.preparation;
          one.characters.push_back(preprocess(source, distances, config.preprocess, mode));
          write_dataset(file, one, 0);  // uncompressed: HDF5's global lock would serialise deflate
        }
      } catch (const std::exception& e) {
        const std::string what = e.what();
        results[k].failure =
            what.find(job.name) == std::string::npos ? job.name + ": " + what : what;
      }
      std::lock_guard<std::mutex> lock(mutex);
      if (progress) progress->tick();
    };
    arena.execute(
        [&] { tbb::parallel_for(std::size_t{0}, jobs.size(), [&](std::size_t k) { work(k); }); });
    if (progress) progress->finish();
    return results;
  };
  // Counts a finished job in the report, or excludes it with its reason.
  const auto tally = [&](const Job& job, const JobResult& result,
                         std::vector<datasets::Excluded>& excluded) {
    if (result.failure) {
      excluded.push_back({characters[job.source].source, characters[job.source].path,
                          *result.failure});
      if (!sharded) spdlog::warn("excluded {}", *result.failure);
      return false;
    }
    (result.reused ? report.reused : report.computed) += 1;
    return true;
  };

  std::vector<Job> originals;
  for (std::size_t i = 0; i < n; ++i) {
    if (mine(i)) originals.push_back({i, -1, characters[i].character.name});
  }
  const std::vector<JobResult> done = run(originals, "prepare");

  if (sharded) {
    // The copies of this shard's characters that train in the splits as they will be if every
    // character prepares (the merge computes the exact splits and any copy still missing).
    std::vector<Job> augmented;
    if (copies > 0) {
      std::vector<std::string> skeleton, source;
      for (const auto& c : characters) {
        skeleton.push_back(c.skeleton);
        source.push_back(c.source);
      }
      const std::vector<bool> trained = trained_in_some_split(
          make_splits(groups, skeleton, source, config.splits), characters.size());
      for (std::size_t k = 0; k < originals.size(); ++k) {
        if (!done[k].failure && trained[originals[k].source]) {
          add_copies(augmented, originals[k].source, originals[k].name, copies);
        }
      }
    }
    const std::vector<JobResult> copied = run(augmented, "augment");
    for (std::size_t k = 0; k < originals.size(); ++k) {
      tally(originals[k], done[k], report.excluded);
    }
    for (std::size_t k = 0; k < augmented.size(); ++k) {
      if (tally(augmented[k], copied[k], report.excluded)) report.copies += 1;
    }
    report.characters = report.computed + report.reused;
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    spdlog::info("shard {} of {}: {} characters ({} of them augmented copies) into {} ({} "
                 "computed, {} reused), {} failed, {:.2f} s",
                 options.shard_index, options.shard_count, report.characters, report.copies,
                 partial.string(), report.computed, report.reused,
                 originals.size() + augmented.size() - report.characters, report.seconds);
    return report;
  }

  Dataset dataset;
  dataset.git_commit = commit;
  dataset.preparation = config.preparation;
  dataset.excluded = report.excluded;
  std::vector<std::size_t> source_of;  // dataset index → index into `characters`
  for (std::size_t k = 0; k < originals.size(); ++k) {
    if (!tally(originals[k], done[k], dataset.excluded)) continue;
    const std::size_t i = originals[k].source;
    Dataset one = read_dataset(partial / (originals[k].name + ".h5"));
    dataset.characters.push_back(std::move(one.characters.at(0)));
    dataset.characters.back().group = groups[i];
    source_of.push_back(i);
  }
  {
    std::vector<std::string> group, skeleton, source;
    for (const auto& c : dataset.characters) {
      group.push_back(c.group);
      skeleton.push_back(c.skeleton);
      source.push_back(c.source);
    }
    dataset.splits = make_splits(group, skeleton, source, config.splits);
  }
  if (copies > 0) {
    // Copies of the characters some split trains on, after every original (whose indices, and
    // so the splits, stay those of the file without augmentation); each joins the train part of
    // every split that trains on its original, and no val or test part.
    const std::vector<bool> trained =
        trained_in_some_split(dataset.splits, dataset.characters.size());
    std::vector<Job> augmented;
    std::vector<int> original_of;  // per job: the original's dataset index
    for (std::size_t d = 0; d < trained.size(); ++d) {
      if (!trained[d]) continue;
      add_copies(augmented, source_of[d], dataset.characters[d].name, copies);
      original_of.resize(augmented.size(), static_cast<int>(d));
    }
    const std::vector<JobResult> copied = run(augmented, "augment");
    std::vector<std::pair<int, int>> joined;  // (original, copy) dataset indices
    for (std::size_t k = 0; k < augmented.size(); ++k) {
      if (!tally(augmented[k], copied[k], dataset.excluded)) continue;
      Dataset one = read_dataset(partial / (augmented[k].name + ".h5"));
      const int original = original_of[k];
      const std::string group = dataset.characters[static_cast<std::size_t>(original)].group;
      dataset.characters.push_back(std::move(one.characters.at(0)));
      dataset.characters.back().group = group;
      joined.emplace_back(original, static_cast<int>(dataset.characters.size()) - 1);
      report.copies += 1;
    }
    for (auto& [name, split] : dataset.splits) {
      const std::set<int> train(split.train.begin(), split.train.end());
      for (const auto& [original, copy] : joined) {
        if (train.count(original)) split.train.push_back(copy);  // copies come last: still sorted
      }
    }
  }
  for (const auto& [name, split] : dataset.splits) {
    spdlog::info("split {}: {} train, {} val, {} test", name, split.train.size(), split.val.size(),
                 split.test.size());
  }
  write_dataset(config.output, dataset);
  report.characters = dataset.characters.size();
  report.excluded = dataset.excluded;
  if (!options.keep_partial) {
    std::error_code ec;
    fs::remove_all(partial, ec);
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("prepared {}: {} characters ({}{} computed, {} reused), {} excluded, {:.2f} s",
               config.output.string(), report.characters,
               report.copies > 0 ? fmt::format("{} of them augmented copies; ", report.copies)
                                 : std::string(),
               report.computed, report.reused, report.excluded.size(), report.seconds);
  return report;
}

}  // namespace skinlab::data

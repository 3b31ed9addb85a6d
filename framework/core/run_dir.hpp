#pragma once
/// \file
/// Run directories: `results/<experiment>/<run_id>/` holding `config.yaml` (the fully resolved
/// config), `env.json`, `log.txt` and `metrics.jsonl` (one JSON object per line). Whole files are
/// written atomically; a run never overwrites an existing run directory.

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace skinlab {

class RunDir {
 public:
  /// Creates `<results_root>/<experiment>/<run_id>/`. An empty `run_id` becomes the UTC time
  /// `YYYYmmdd-HHMMSS`, with `-2`, `-3`, ... appended while that name is taken. An explicit
  /// `run_id` that already exists is an error: runs are never overwritten. Names may contain
  /// letters, digits, '_', '-' and '.', and may not start with '.'.
  static RunDir create(const std::filesystem::path& results_root, const std::string& experiment,
                       const std::string& run_id = "");

  /// Opens an existing run directory (for evaluation or resuming). Throws if it is not one.
  static RunDir open(const std::filesystem::path& dir);

  const std::filesystem::path& path() const { return path_; }
  std::string id() const { return path_.filename().string(); }
  /// `<dir>/<name>`.
  std::filesystem::path file(const std::string& name) const { return path_ / name; }

  /// Writes `config.yaml` (atomically).
  void write_config(const std::string& resolved_yaml) const;
  /// Writes `env.json` (atomically).
  void write_env(const nlohmann::json& env) const;
  /// Appends `record` to the `resumes` list of `env.json` (atomically; the list is created on
  /// the first resume). env.json describes the code a run started with; a run resumed from
  /// last.pt by another build says so here, so every epoch stays traceable to its commit.
  void record_resume(const nlohmann::json& record) const;
  /// Appends one record to `metrics.jsonl`. The file is rewritten atomically, so a crash leaves
  /// every line complete.
  void append_metrics(const nlohmann::json& record) const;
  /// Every record of `metrics.jsonl`, in order. A malformed line is an error naming the line.
  std::vector<nlohmann::json> read_metrics() const;
  /// `log.txt`, for the logger's file sink.
  std::filesystem::path log_file() const { return file("log.txt"); }

 private:
  explicit RunDir(std::filesystem::path path) : path_(std::move(path)) {}
  std::filesystem::path path_;
};

}  // namespace skinlab

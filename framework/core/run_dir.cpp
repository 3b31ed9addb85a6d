#include "framework/core/run_dir.hpp"

#include <array>
#include <ctime>
#include <sstream>

#include "framework/core/atomic_file.hpp"
#include "framework/core/error.hpp"

namespace skinlab {

namespace fs = std::filesystem;

namespace {

void check_name(const std::string& name, const std::string& what) {
  const bool ok = !name.empty() && name[0] != '.' &&
                  name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                         "0123456789_-.") == std::string::npos;
  if (!ok) {
    throw Error(what + " '" + name +
                "' is not a valid directory name (letters, digits, '_', '-', '.'; not starting "
                "with '.')");
  }
}

std::string timestamp_id() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  ::gmtime_r(&now, &utc);
  std::array<char, 32> text{};
  std::strftime(text.data(), text.size(), "%Y%m%d-%H%M%S", &utc);
  return text.data();
}

}  // namespace

RunDir RunDir::create(const fs::path& results_root, const std::string& experiment,
                      const std::string& run_id) {
  check_name(experiment, "experiment name");
  if (!run_id.empty()) check_name(run_id, "run id");
  const fs::path parent = results_root / experiment;
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) throw IoError(parent.string() + ": cannot create directory: " + ec.message());

  if (!run_id.empty()) {
    const fs::path dir = parent / run_id;
    // create_directory is the atomic existence test: false means someone has that run already.
    if (!fs::create_directory(dir, ec)) {
      throw Error(dir.string() + ": run directory already exists; runs are never overwritten "
                  "(choose another run id or remove it)" + (ec ? ": " + ec.message() : ""));
    }
    return RunDir(dir);
  }
  const std::string base = timestamp_id();
  for (int n = 1; n < 10000; ++n) {
    const fs::path dir = parent / (n == 1 ? base : base + "-" + std::to_string(n));
    if (fs::create_directory(dir, ec)) return RunDir(dir);
    if (ec) throw IoError(dir.string() + ": cannot create run directory: " + ec.message());
  }
  throw Error(parent.string() + ": too many runs named " + base);
}

RunDir RunDir::open(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw Error(dir.string() + ": run directory does not exist");
  if (!fs::exists(dir / "config.yaml")) {
    throw Error(dir.string() + ": not a run directory (no config.yaml)");
  }
  return RunDir(dir);
}

void RunDir::write_config(const std::string& resolved_yaml) const {
  write_file_atomic(file("config.yaml"), resolved_yaml);
}

void RunDir::write_env(const nlohmann::json& env) const {
  write_file_atomic(file("env.json"), env.dump(2) + "\n");
}

void RunDir::record_resume(const nlohmann::json& record) const {
  const fs::path target = file("env.json");
  nlohmann::json env = nlohmann::json::object();
  if (fs::exists(target)) {
    env = nlohmann::json::parse(read_file(target), nullptr, /*allow_exceptions=*/false);
    if (!env.is_object()) throw Error(target.string() + ": not a JSON object");
  }
  if (!env.contains("resumes")) env["resumes"] = nlohmann::json::array();
  if (!env["resumes"].is_array()) throw Error(target.string() + ": 'resumes' is not a list");
  env["resumes"].push_back(record);
  write_env(env);
}

void RunDir::append_metrics(const nlohmann::json& record) const {
  if (!record.is_object()) throw Error(file("metrics.jsonl").string() + ": a metrics record must be a JSON object");
  const fs::path target = file("metrics.jsonl");
  std::string contents = fs::exists(target) ? read_file(target) : std::string();
  contents += record.dump() + "\n";
  write_file_atomic(target, contents);
}

std::vector<nlohmann::json> RunDir::read_metrics() const {
  const fs::path target = file("metrics.jsonl");
  std::vector<nlohmann::json> out;
  if (!fs::exists(target)) return out;
  std::istringstream lines(read_file(target));
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    if (line.empty()) continue;
    try {
      out.push_back(nlohmann::json::parse(line));
    } catch (const nlohmann::json::parse_error& e) {
      throw Error(target.string() + ":" + std::to_string(number) + ": malformed JSON: " + e.what());
    }
  }
  return out;
}

}  // namespace skinlab

#include "datasets/repository.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>

#include "framework/core/error.hpp"

namespace skinlab::datasets {

namespace fs = std::filesystem;

namespace {

bool is_repository(const std::string& s) {
  const auto slash = s.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == s.size() ||
      s.find('/', slash + 1) != std::string::npos) {
    return false;
  }
  return std::all_of(s.begin(), s.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '/';
  }) && s[0] != '.' && s[slash + 1] != '.';
}

bool is_commit(const std::string& s) {
  return s.size() == 40 && std::all_of(s.begin(), s.end(), [](unsigned char c) {
           return std::isdigit(c) || (c >= 'a' && c <= 'f');
         });
}

/// The commit a git checkout's HEAD names directly (a detached checkout, as fetch_data leaves
/// it), or "" when it cannot be told (no .git, a branch ref).
std::string checked_out_commit(const fs::path& dir) {
  std::ifstream in(dir / ".git" / "HEAD");
  std::string head;
  if (!(in >> head) || !is_commit(head)) return "";
  return head;
}

}  // namespace

RepositorySource RepositorySource::from(config::Fields& f, const config::Node& node) {
  RepositorySource o;
  f.optional("source", o.name);
  f.optional("repository", o.repository);
  f.optional("commit", o.commit);
  if (o.repository.empty()) {
    f.required("path", o.path);
    f.check(!o.path.empty(), "path", "must not be empty");
  } else {
    f.optional("path", o.path);
  }
  f.check(o.repository.empty() || is_repository(o.repository), "repository",
          "expected owner/name of a GitHub repository, got '" + o.repository + "'");
  f.check(o.repository.empty() || !o.commit.empty(), "commit",
          "is required with 'repository' (40 hex digits), so the data is reproducible");
  f.check(o.commit.empty() || !o.repository.empty(), "commit",
          "is only meaningful with 'repository: owner/name'");
  f.check(o.commit.empty() || is_commit(o.commit), "commit",
          "expected a full commit id of 40 lowercase hex digits, got '" + o.commit + "'");
  f.check(o.repository.empty() ||
              (!fs::path(o.path).is_absolute() &&
               fs::path(o.path).lexically_normal().generic_string().rfind("..", 0) != 0),
          "path", "must be a directory inside the repository (relative, without '..')");
  o.where = node.where();
  o.config_file = node.origin().file;
  return o;
}

std::string RepositorySource::label(const std::string& builder) const {
  if (!name.empty()) return name;
  return repository.empty() ? builder : repository;
}

fs::path RepositorySource::root(const std::string& builder) const {
  if (repository.empty()) return fs::path(path);
  const std::string fetch =
      "; fetch it with `scripts/fetch_data " +
      (config_file.empty() ? std::string("<dataset config>") : config_file) + "`";
  const std::string owner = where + "dataset '" + builder + "': ";
  const char* data_dir = std::getenv("SKINLAB_DATA_DIR");
  const std::string repo = "repository " + repository + " at commit " + commit;
  if (data_dir == nullptr || *data_dir == '\0') {
    throw IoError(owner + repo +
                  ": the environment variable SKINLAB_DATA_DIR is not set; it names the data "
                  "folder that holds <owner>/<name>/ (expected " + repository +
                  "/ under it)" + fetch + " and export SKINLAB_DATA_DIR");
  }
  const fs::path checkout = fs::path(data_dir) / repository;
  std::error_code ec;
  if (!fs::is_directory(checkout, ec)) {
    throw IoError(owner + repo + " is not in the data folder: expected " + checkout.string() +
                  " (SKINLAB_DATA_DIR=" + data_dir + ")" + fetch);
  }
  const std::string head = checked_out_commit(checkout);
  if (!head.empty() && head != commit) {
    throw IoError(owner + checkout.string() + " is checked out at " + head +
                  ", but the config names commit " + commit + fetch);
  }
  return path.empty() ? checkout : checkout / path;
}

}  // namespace skinlab::datasets

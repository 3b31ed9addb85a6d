#include "datasets/zeroad/package.hpp"

#include <zip.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

#include "framework/core/error.hpp"

namespace skinlab::datasets::zeroad {

namespace fs = std::filesystem;

struct Package::Impl {
  zip_t* archive = nullptr;  // null for a directory
  fs::path root;
  std::map<std::string, zip_uint64_t> entries;  // path -> archive index, or 0 for a directory
};

Package::Package(const fs::path& path) : impl_(std::make_unique<Impl>()), name_(path.string()) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    impl_->root = path;
    for (auto it = fs::recursive_directory_iterator(path, ec); !ec && it != fs::end(it);
         it.increment(ec)) {
      if (!it->is_regular_file()) continue;
      impl_->entries.emplace(fs::relative(it->path(), path).generic_string(), 0);
    }
    if (ec) throw IoError(name_ + ": cannot list directory: " + ec.message());
    return;
  }
  if (!fs::is_regular_file(path, ec)) {
    throw IoError(name_ + ": no such zip archive or directory");
  }
  int error = 0;
  impl_->archive = zip_open(name_.c_str(), ZIP_RDONLY, &error);
  if (!impl_->archive) {
    zip_error_t z;
    zip_error_init_with_code(&z, error);
    const std::string message = zip_error_strerror(&z);
    zip_error_fini(&z);
    throw IoError(name_ + ": cannot open as a zip archive: " + message);
  }
  const zip_int64_t n = zip_get_num_entries(impl_->archive, 0);
  for (zip_int64_t i = 0; i < n; ++i) {
    const char* entry = zip_get_name(impl_->archive, static_cast<zip_uint64_t>(i), 0);
    if (!entry) continue;
    std::string s(entry);
    if (s.empty() || s.back() == '/') continue;
    impl_->entries.emplace(std::move(s), static_cast<zip_uint64_t>(i));
  }
}

Package::~Package() {
  if (impl_ && impl_->archive) zip_discard(impl_->archive);
}

std::vector<std::string> Package::list(const std::string& prefix, const std::string& suffix) const {
  std::vector<std::string> out;
  for (auto it = impl_->entries.lower_bound(prefix);
       it != impl_->entries.end() && it->first.compare(0, prefix.size(), prefix) == 0; ++it) {
    const std::string& e = it->first;
    if (e.size() >= suffix.size() &&
        e.compare(e.size() - suffix.size(), suffix.size(), suffix) == 0)
      out.push_back(e);
  }
  return out;  // std::map keeps them sorted
}

bool Package::contains(const std::string& entry) const { return impl_->entries.count(entry) > 0; }

std::string Package::read(const std::string& entry) const {
  auto it = impl_->entries.find(entry);
  if (it == impl_->entries.end()) throw IoError(name_ + ": no entry '" + entry + "'");
  if (!impl_->archive) {
    std::ifstream in(impl_->root / entry, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    if (!in) throw IoError(name_ + ": cannot read '" + entry + "'");
    return bytes.str();
  }
  zip_stat_t st;
  zip_stat_init(&st);
  if (zip_stat_index(impl_->archive, it->second, 0, &st) != 0 || !(st.valid & ZIP_STAT_SIZE)) {
    throw IoError(name_ + ": cannot stat '" + entry + "': " + zip_strerror(impl_->archive));
  }
  zip_file_t* file = zip_fopen_index(impl_->archive, it->second, 0);
  if (!file) {
    throw IoError(name_ + ": cannot open '" + entry + "': " + zip_strerror(impl_->archive));
  }
  std::string bytes(static_cast<std::size_t>(st.size), '\0');
  zip_uint64_t done = 0;
  while (done < st.size) {
    const zip_int64_t got = zip_fread(file, bytes.data() + done, st.size - done);
    if (got <= 0) break;
    done += static_cast<zip_uint64_t>(got);
  }
  zip_fclose(file);
  if (done != st.size) {
    throw IoError(name_ + ": '" + entry + "' is truncated (read " + std::to_string(done) + " of " +
                  std::to_string(st.size) + " bytes)");
  }
  return bytes;
}

}  // namespace skinlab::datasets::zeroad

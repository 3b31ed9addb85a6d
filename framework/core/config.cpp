#include "framework/core/config.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <map>
#include <set>

namespace skinlab::config {

namespace fs = std::filesystem;

namespace detail {

/// The resolved document and, for every key path, where it was defined.
struct Tree {
  YAML::Node root;
  std::map<std::string, Origin> origins;
  std::string source;
};

struct NodeImpl {
  std::shared_ptr<const Tree> tree;
  YAML::Node node{YAML::NodeType::Undefined};  // undefined for a missing key
  std::string path;
};

}  // namespace detail

namespace {

using Origins = std::map<std::string, Origin>;

std::string child_path(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}
std::string index_path(const std::string& parent, std::size_t i) {
  return parent + "[" + std::to_string(i) + "]";
}

/// Path of the parent of `path` ("" for a top-level key).
std::string parent_path(const std::string& path) {
  const auto pos = path.find_last_of(".[");
  return pos == std::string::npos ? std::string() : path.substr(0, pos);
}

bool is_under(const std::string& key, const std::string& prefix) {
  if (key.size() < prefix.size() || key.compare(0, prefix.size(), prefix) != 0) return false;
  return key.size() == prefix.size() || key[prefix.size()] == '.' || key[prefix.size()] == '[';
}

void erase_under(Origins& origins, const std::string& prefix) {
  for (auto it = origins.lower_bound(prefix); it != origins.end();) {
    if (it->first.compare(0, prefix.size(), prefix) != 0) break;
    it = is_under(it->first, prefix) ? origins.erase(it) : std::next(it);
  }
}

void copy_under(const Origins& from, Origins& to, const std::string& prefix) {
  for (auto it = from.lower_bound(prefix); it != from.end(); ++it) {
    if (it->first.compare(0, prefix.size(), prefix) != 0) break;
    if (is_under(it->first, prefix)) to[it->first] = it->second;
  }
}

std::string scalar_text(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "null";
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsMap()) return "a map";
  return "a list";
}

/// Records the origin of every value under `node`, and checks that map keys are scalars.
void record_origins(const YAML::Node& node, const std::string& path, const std::string& file,
                    Origins& origins) {
  origins[path] = Origin{file, node.Mark().line + 1};
  if (node.IsMap()) {
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) {
        throw ConfigError(file + ":" + std::to_string(kv.first.Mark().line + 1) + ": " +
                          (path.empty() ? "" : path + ": ") + "map keys must be plain strings");
      }
      record_origins(kv.second, child_path(path, kv.first.Scalar()), file, origins);
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      record_origins(node[i], index_path(path, i), file, origins);
    }
  }
}

/// Deep-merges map `src` into map `dst`: maps merge key by key, anything else replaces.
void merge_into(YAML::Node dst, Origins& dst_origins, const YAML::Node& src,
                const Origins& src_origins, const std::string& path) {
  for (const auto& kv : src) {
    const std::string key = kv.first.Scalar();
    const std::string p = child_path(path, key);
    const YAML::Node& cdst = dst;
    const YAML::Node existing = cdst[key];
    if (existing.IsDefined() && existing.IsMap() && kv.second.IsMap()) {
      merge_into(existing, dst_origins, kv.second, src_origins, p);
      if (auto it = src_origins.find(p); it != src_origins.end()) dst_origins[p] = it->second;
    } else {
      dst[key] = YAML::Clone(kv.second);
      erase_under(dst_origins, p);
      copy_under(src_origins, dst_origins, p);
    }
  }
}

YAML::Node load_yaml_file(const fs::path& file, const std::string& display) {
  if (!fs::exists(file)) throw ConfigError(display + ": config file does not exist");
  try {
    return YAML::LoadFile(file.string());
  } catch (const YAML::ParserException& e) {
    throw ConfigError(display + ":" + std::to_string(e.mark.line + 1) + ":" +
                      std::to_string(e.mark.column + 1) + ": YAML syntax error: " + e.msg);
  } catch (const YAML::BadFile&) {
    throw ConfigError(display + ": cannot read config file");
  }
}

struct Loaded {
  YAML::Node root;
  Origins origins;
};

/// Loads `file` with its `_base_` chain. `chain` holds the canonical paths being loaded, for
/// cycle detection.
Loaded load_with_bases(const fs::path& file, std::vector<fs::path>& chain) {
  const std::string display = file.lexically_normal().string();
  const fs::path canonical = fs::weakly_canonical(file);
  if (std::find(chain.begin(), chain.end(), canonical) != chain.end()) {
    std::string cycle;
    for (const auto& p : chain) cycle += p.filename().string() + " -> ";
    throw ConfigError(display + ": _base_ cycle: " + cycle + canonical.filename().string());
  }
  YAML::Node node = load_yaml_file(file, display);
  if (!node.IsDefined() || node.IsNull()) node = YAML::Node(YAML::NodeType::Map);
  if (!node.IsMap()) {
    throw ConfigError(display + ":" + std::to_string(node.Mark().line + 1) +
                      ": the top level of a config must be a map of keys");
  }
  Origins own;
  record_origins(node, "", display, own);

  std::vector<std::pair<std::string, int>> bases;  // (relative path, line)
  if (const YAML::Node b = static_cast<const YAML::Node&>(node)["_base_"]; b.IsDefined()) {
    const int line = b.Mark().line + 1;
    auto bad = [&] {
      throw ConfigError(display + ":" + std::to_string(line) +
                        ": _base_: expected a file name or a list of file names");
    };
    if (b.IsScalar()) {
      bases.emplace_back(b.Scalar(), line);
    } else if (b.IsSequence()) {
      for (const auto& e : b) {
        if (!e.IsScalar()) bad();
        bases.emplace_back(e.Scalar(), e.Mark().line + 1);
      }
    } else {
      bad();
    }
    node.remove("_base_");
    erase_under(own, "_base_");
  }

  chain.push_back(canonical);
  Loaded result{YAML::Node(YAML::NodeType::Map), {}};
  for (const auto& [rel, line] : bases) {
    const fs::path base_file = file.parent_path() / rel;
    if (!fs::exists(base_file)) {
      throw ConfigError(display + ":" + std::to_string(line) + ": _base_: file '" +
                        base_file.lexically_normal().string() + "' does not exist");
    }
    Loaded base = load_with_bases(base_file, chain);
    merge_into(result.root, result.origins, base.root, base.origins, "");
  }
  chain.pop_back();
  merge_into(result.root, result.origins, node, own, "");
  result.origins[""] = Origin{display, 1};
  return result;
}

/// Splits "a.b[0].c" / "a.b.0.c" into segments.
std::vector<std::string> split_key_path(const std::string& key, const std::string& assignment) {
  std::vector<std::string> parts;
  std::string cur;
  auto flush = [&] {
    if (cur.empty()) throw ConfigError("override '" + assignment + "': empty key segment");
    parts.push_back(cur);
    cur.clear();
  };
  for (std::size_t i = 0; i < key.size(); ++i) {
    const char c = key[i];
    if (c == '.') {
      if (i > 0 && key[i - 1] == ']') continue;
      flush();
    } else if (c == '[') {
      flush();
    } else if (c == ']') {
      flush();
    } else {
      cur += c;
    }
  }
  if (!cur.empty() || key.empty() || key.back() != ']') flush();
  return parts;
}

bool parse_index(const std::string& s, std::size_t& out) {
  if (s.empty() || !std::all_of(s.begin(), s.end(), ::isdigit)) return false;
  out = std::stoul(s);
  return true;
}

template <class T>
bool decode_scalar(const YAML::Node& node, T& out) {
  if (!node.IsScalar()) return false;
  return YAML::convert<T>::decode(node, out);
}

}  // namespace

template <> std::string expected_name<bool>() { return "a boolean (true/false)"; }
template <> std::string expected_name<int>() { return "an integer"; }
template <> std::string expected_name<std::int64_t>() { return "an integer"; }
template <> std::string expected_name<double>() { return "a number"; }
template <> std::string expected_name<float>() { return "a number"; }
template <> std::string expected_name<std::string>() { return "a string"; }
template <> std::string expected_name<std::vector<bool>>() { return "a list of booleans"; }
template <> std::string expected_name<std::vector<int>>() { return "a list of integers"; }
template <> std::string expected_name<std::vector<std::int64_t>>() { return "a list of integers"; }
template <> std::string expected_name<std::vector<double>>() { return "a list of numbers"; }
template <> std::string expected_name<std::vector<float>>() { return "a list of numbers"; }
template <> std::string expected_name<std::vector<std::string>>() { return "a list of strings"; }

// ---- Origin -------------------------------------------------------------------------------------

std::string Origin::str() const {
  if (file.empty()) return "";
  return line > 0 ? file + ":" + std::to_string(line) : file;
}

// ---- Node ---------------------------------------------------------------------------------------

Node::Node() : impl_(std::make_shared<detail::NodeImpl>()) {}
Node::Node(std::shared_ptr<const detail::NodeImpl> impl) : impl_(std::move(impl)) {}

bool Node::exists() const { return impl_->node.IsDefined(); }
bool Node::is_null() const { return !exists() || impl_->node.IsNull(); }
bool Node::is_map() const { return exists() && impl_->node.IsMap(); }
bool Node::is_sequence() const { return exists() && impl_->node.IsSequence(); }
bool Node::is_scalar() const { return exists() && impl_->node.IsScalar(); }

std::size_t Node::size() const { return is_map() || is_sequence() ? impl_->node.size() : 0; }

std::vector<std::string> Node::keys() const {
  std::vector<std::string> out;
  if (is_map()) {
    for (const auto& kv : impl_->node) out.push_back(kv.first.Scalar());
  }
  return out;
}

bool Node::has(const std::string& key) const { return (*this)[key].exists(); }

Node Node::operator[](const std::string& key) const {
  auto child = std::make_shared<detail::NodeImpl>();
  child->tree = impl_->tree;
  child->path = child_path(impl_->path, key);
  if (is_map()) {
    // A missing key gives an invalid node that must not be reset() into a view.
    const YAML::Node found = static_cast<const YAML::Node&>(impl_->node)[key];
    if (found.IsDefined()) child->node.reset(found);
  }
  return Node(std::move(child));
}

Node Node::operator[](std::size_t index) const {
  auto child = std::make_shared<detail::NodeImpl>();
  child->tree = impl_->tree;
  child->path = index_path(impl_->path, index);
  if (is_sequence() && index < impl_->node.size()) {
    child->node.reset(static_cast<const YAML::Node&>(impl_->node)[index]);
  }
  return Node(std::move(child));
}

const std::string& Node::path() const { return impl_->path; }

Origin Node::origin() const {
  if (!impl_->tree) return {};
  const auto& origins = impl_->tree->origins;
  std::string p = impl_->path;
  while (true) {
    if (auto it = origins.find(p); it != origins.end()) return it->second;
    if (p.empty()) return Origin{impl_->tree->source, 0};
    p = parent_path(p);
  }
}

std::string Node::where() const {
  std::string out = origin().str();
  if (!out.empty()) out += ": ";
  if (!impl_->path.empty()) out += impl_->path + ": ";
  return out;
}

void Node::fail(const std::string& message) const { throw ConfigError(where() + message); }

std::string Node::required_type(const std::string& category) const {
  if (!exists()) fail("missing " + category + " section (expected a map with a 'type' key)");
  if (!is_map()) {
    fail("expected a map with a 'type' key naming the " + category + ", got " +
         scalar_text(impl_->node));
  }
  const Node type = (*this)["type"];
  if (!type.exists()) {
    fail("missing required field 'type' (expected the name of a registered " + category + ")");
  }
  if (!type.is_scalar()) type.fail("expected a " + category + " name, got " + scalar_text(type.impl_->node));
  return type.impl_->node.Scalar();
}

std::string Node::to_yaml() const {
  if (!exists()) return "";
  YAML::Emitter out;
  out << impl_->node;
  return std::string(out.c_str()) + "\n";
}

template <class T>
T Node::as() const {
  if (!exists()) fail("missing value (expected " + expected_name<T>() + ")");
  T out{};
  if (!decode_scalar(impl_->node, out)) {
    fail("expected " + expected_name<T>() + ", got " + scalar_text(impl_->node));
  }
  return out;
}

template <>
std::string Node::as<std::string>() const {
  if (!exists()) fail("missing value (expected a string)");
  if (!impl_->node.IsScalar()) fail("expected a string, got " + scalar_text(impl_->node));
  return impl_->node.Scalar();
}

#define SKINLAB_CONFIG_VECTOR_AS(T)                                             \
  template <>                                                                   \
  std::vector<T> Node::as<std::vector<T>>() const {                             \
    if (!is_sequence()) {                                                       \
      fail("expected " + expected_name<std::vector<T>>() + ", got " +           \
           (exists() ? scalar_text(impl_->node) : std::string("nothing")));     \
    }                                                                           \
    std::vector<T> out;                                                         \
    for (std::size_t i = 0; i < size(); ++i) out.push_back((*this)[i].as<T>()); \
    return out;                                                                 \
  }
SKINLAB_CONFIG_VECTOR_AS(bool)
SKINLAB_CONFIG_VECTOR_AS(int)
SKINLAB_CONFIG_VECTOR_AS(std::int64_t)
SKINLAB_CONFIG_VECTOR_AS(double)
SKINLAB_CONFIG_VECTOR_AS(float)
SKINLAB_CONFIG_VECTOR_AS(std::string)
#undef SKINLAB_CONFIG_VECTOR_AS

template bool Node::as<bool>() const;
template int Node::as<int>() const;
template std::int64_t Node::as<std::int64_t>() const;
template double Node::as<double>() const;
template float Node::as<float>() const;

// ---- Config -------------------------------------------------------------------------------------

Config Config::load(const fs::path& file, const std::vector<std::string>& overrides) {
  std::vector<fs::path> chain;
  Loaded loaded = load_with_bases(file, chain);
  Config config;
  config.tree_ = std::make_shared<detail::Tree>(
      detail::Tree{loaded.root, std::move(loaded.origins), file.lexically_normal().string()});
  for (const auto& o : overrides) config.apply_override(o);
  return config;
}

Config Config::parse(const std::string& yaml, const std::string& source_name) {
  YAML::Node node;
  try {
    node = YAML::Load(yaml);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(source_name + ":" + std::to_string(e.mark.line + 1) +
                      ": YAML syntax error: " + e.msg);
  }
  if (!node.IsDefined() || node.IsNull()) node = YAML::Node(YAML::NodeType::Map);
  if (!node.IsMap()) throw ConfigError(source_name + ": the top level of a config must be a map");
  Config config;
  config.tree_ = std::make_shared<detail::Tree>(detail::Tree{node, {}, source_name});
  record_origins(node, "", source_name, config.tree_->origins);
  return config;
}

void Config::apply_override(const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw ConfigError("override '" + assignment + "': expected key.path=value");
  }
  const std::string key = assignment.substr(0, eq);
  const std::string value_text = assignment.substr(eq + 1);
  const std::vector<std::string> parts = split_key_path(key, assignment);
  if (parts.front() == "_base_") {
    throw ConfigError("override '" + assignment + "': _base_ cannot be overridden");
  }
  YAML::Node value;
  try {
    value = YAML::Load(value_text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError("override '" + assignment + "': value is not valid YAML: " + e.msg);
  }

  // Copy on write: views taken before the override keep seeing the old tree.
  // (YAML::Node assignment writes through aliases, hence reset() on a fresh node.)
  auto tree = std::make_shared<detail::Tree>();
  tree->root.reset(YAML::Clone(tree_->root));
  tree->origins = tree_->origins;
  tree->source = tree_->source;

  const std::string source = "override '" + assignment + "'";
  YAML::Node cur;
  cur.reset(tree->root);
  std::string path;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    YAML::Node slot;
    if (cur.IsSequence()) {
      std::size_t index = 0;
      if (!parse_index(part, index) || index >= cur.size()) {
        throw ConfigError(source + ": '" + path + "' is a list of " + std::to_string(cur.size()) +
                          " entries; '" + part + "' is not a valid index");
      }
      path = index_path(path, index);
      slot.reset(cur[index]);
    } else if (cur.IsScalar()) {
      throw ConfigError(source + ": '" + path + "' is a value, not a map; cannot set a key under it");
    } else {
      path = child_path(path, part);
      const YAML::Node& ccur = cur;
      if (!last && (!ccur[part].IsDefined() || ccur[part].IsNull())) {
        cur[part] = YAML::Node(YAML::NodeType::Map);  // intermediate maps are created
        tree->origins[path] = Origin{source, 0};
      }
      slot.reset(cur[part]);
    }
    if (last) {
      slot = value;  // writes through into the tree
    } else {
      cur.reset(slot);
    }
  }
  erase_under(tree->origins, path);
  Origins value_origins;
  record_origins(value, path, source, value_origins);
  for (auto& [p, o] : value_origins) {
    o.line = 0;
    tree->origins[p] = o;
  }
  tree_ = std::move(tree);
}

Node Config::root() const {
  auto impl = std::make_shared<detail::NodeImpl>();
  impl->tree = tree_;
  impl->node.reset(tree_->root);
  return Node(std::move(impl));
}

std::string Config::to_yaml() const { return root().to_yaml(); }

const std::string& Config::source() const { return tree_->source; }

// ---- Fields -------------------------------------------------------------------------------------

namespace {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

Fields::Fields(Node node, std::string owner, std::vector<std::string> reserved)
    : node_(std::move(node)), owner_(std::move(owner)), known_(std::move(reserved)) {
  if (node_.exists() && !node_.is_null() && !node_.is_map()) {
    node_.fail("expected a map of options for " + owner_);
  }
}

void Fields::declare(const std::string& key) {
  if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.push_back(key);
}

Node Fields::section(const std::string& key) {
  declare(key);
  return node_[key];
}

Fields& Fields::check(bool ok, const std::string& key, const std::string& message) {
  if (!ok) {
    const Node child = node_[key];
    (child.exists() ? child : node_).fail(child.exists() ? message : key + " " + message);
  }
  return *this;
}

void Fields::missing(const std::string& key, const std::string& expected) const {
  node_.fail("missing required field '" + key + "' of " + owner_ + " (expected " + expected + ")");
}

void Fields::finish() const {
  std::vector<std::string> known = known_;
  std::sort(known.begin(), known.end());
  for (const auto& key : node_.keys()) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string list, best;
    std::size_t best_distance = 3;  // suggest only close matches
    for (const auto& k : known) {
      list += (list.empty() ? "" : ", ") + k;
      if (const auto d = edit_distance(key, k); d < best_distance) best_distance = d, best = k;
    }
    node_[key].fail("unknown field of " + owner_ +
                    (best.empty() ? "" : " (did you mean '" + best + "'?)") +
                    "; known fields: " + (list.empty() ? "(none)" : list));
  }
}

}  // namespace skinlab::config

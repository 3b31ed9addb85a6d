#pragma once
/// \file
/// The config layer: YAML files with `_base_:` inheritance, command-line overrides and typed
/// decoding into per-plug-in options structs. It is the only code that touches `YAML::Node`
/// so that everything else sees `config::Node`.
///
/// Semantics (as in mmengine/detectron2):
/// - `_base_: file.yaml` or `_base_: [a.yaml, b.yaml]`: paths relative to the including file;
///   bases are merged in order, then the including file on top; chains are followed and cycles
///   are an error.
/// - Merging is deep for maps; any other value (scalar or list) replaces the base's value.
/// - Overrides `key.sub=value` (or `list.0.key=value`, `list[0].key=value`) are applied after all
///   files; the value is parsed as YAML, so `3` is an integer, `0.5` a number, `[1, 2]` a list.
/// - Every value remembers where it came from, so errors read `file:line: key.path: message`.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/core/error.hpp"

namespace skinlab::config {

/// Where a value was defined.
struct Origin {
  std::string file;  ///< config file, or a description such as "override 'a.b=3'"
  int line = 0;      ///< 1-based line in `file`, 0 when unknown
  /// "file:line", "file", or "" when nothing is known.
  std::string str() const;
};

namespace detail {
struct Tree;
struct NodeImpl;
}  // namespace detail

/// A read-only view of one value in a resolved config. A view of a key that does not exist is
/// valid: `exists()` is false and reading it throws an error naming the key.
class Node {
 public:
  Node();

  bool exists() const;
  bool is_null() const;  ///< missing, or present with no value (`key:`)
  bool is_map() const;
  bool is_sequence() const;
  bool is_scalar() const;
  /// Number of entries of a map or list, 0 otherwise.
  std::size_t size() const;
  /// Keys of a map in file order.
  std::vector<std::string> keys() const;
  bool has(const std::string& key) const;

  /// Child of a map (a view of a missing key when absent or when this is not a map).
  Node operator[](const std::string& key) const;
  Node operator[](const char* key) const { return (*this)[std::string(key)]; }
  /// Element of a list.
  Node operator[](std::size_t index) const;
  Node operator[](int index) const {  // (a literal 0 would otherwise be ambiguous with char*)
    return (*this)[static_cast<std::size_t>(index)];  // negative: a huge index, i.e. missing
  }

  /// Decodes the value. Supported: bool, int, std::int64_t, double, float, std::string and
  /// std::vector of those. Throws ConfigError "file:line: path: expected <what>, got <value>".
  template <class T>
  T as() const;

  /// Dotted key path from the root, e.g. `losses[1].weight`; empty for the root.
  const std::string& path() const;
  /// Origin of this value, or of its nearest existing ancestor.
  Origin origin() const;
  /// Message prefix "file:line: path: " (parts omitted when unknown).
  std::string where() const;
  /// Throws ConfigError(where() + message).
  [[noreturn]] void fail(const std::string& message) const;

  /// The `type:` key of a plug-in node; a missing or non-string type is an error naming
  /// `category` ("loss", "model", ...).
  std::string required_type(const std::string& category) const;

  /// The subtree as YAML text.
  std::string to_yaml() const;

 private:
  friend class Config;
  explicit Node(std::shared_ptr<const detail::NodeImpl> impl);
  std::shared_ptr<const detail::NodeImpl> impl_;
};

/// A fully resolved configuration (all bases merged, overrides applied).
class Config {
 public:
  /// Loads `file` and its `_base_` chain, then applies `overrides` in order.
  static Config load(const std::filesystem::path& file,
                     const std::vector<std::string>& overrides = {});
  /// Parses YAML text (no `_base_` resolution relative to a directory other than the cwd).
  static Config parse(const std::string& yaml, const std::string& source_name = "<string>");

  /// Applies one `key.sub=value` assignment.
  void apply_override(const std::string& assignment);

  Node root() const;
  /// The resolved config as YAML text (what a run saves as `config.yaml`).
  std::string to_yaml() const;
  /// The file the config was loaded from (or the source name given to `parse`).
  const std::string& source() const;

 private:
  Config() = default;
  std::shared_ptr<detail::Tree> tree_;
};

/// Human-readable expectation for a decoded type ("an integer", "a list of numbers", ...).
template <class T>
std::string expected_name();

/// Typed decoding of one plug-in's options map, with unknown-key detection:
///
///     KlOptions o;
///     config::Fields f(node, "loss 'kl'", {"type", "weight"});
///     f.optional("eps", o.eps);
///     f.check(o.eps > 0, "eps", "must be positive");
///     f.finish();  // a key not read above is an error listing the known fields
class Fields {
 public:
  /// `owner` names what is configured in messages. `reserved` keys are accepted without being
  /// read here (they belong to the caller, e.g. `type`). A missing or null node is an empty map.
  Fields(Node node, std::string owner, std::vector<std::string> reserved = {"type"});

  /// Reads `key` into `value` when present; leaves the default otherwise.
  template <class T>
  Fields& optional(const std::string& key, T& value) {
    declare(key);
    Node child = node_[key];
    if (child.exists()) value = child.template as<T>();
    return *this;
  }

  /// Reads `key` into `value`; absent is an error naming the owner and the expected type.
  template <class T>
  Fields& required(const std::string& key, T& value) {
    declare(key);
    Node child = node_[key];
    if (!child.exists()) missing(key, expected_name<T>());
    value = child.template as<T>();
    return *this;
  }

  /// Declares `key` as a known field and returns its node (possibly missing), for nested
  /// sections decoded elsewhere (e.g. a plug-in node).
  Node section(const std::string& key);

  /// Throws ConfigError at `key` with `message` unless `ok`.
  Fields& check(bool ok, const std::string& key, const std::string& message);

  /// Throws on the first key that was neither read nor reserved, listing the known fields and
  /// suggesting the closest one.
  void finish() const;

 private:
  void declare(const std::string& key);
  [[noreturn]] void missing(const std::string& key, const std::string& expected) const;
  Node node_;
  std::string owner_;
  std::vector<std::string> known_;
};

}  // namespace skinlab::config

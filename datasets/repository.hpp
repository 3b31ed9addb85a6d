#pragma once
/// \file
/// A source that names a public GitHub repository and commit (`repository: owner/name`,
/// `commit: <40 hex>`, `path` inside it), shared by the builders that read such sources
/// (`folder`, `ogre`). The files are in `${SKINLAB_DATA_DIR}/<owner>/<name>/`, where
/// `scripts/fetch_data <dataset config>` clones the repository at that commit; nothing is
/// downloaded by the program itself.

#include <filesystem>
#include <string>

#include "framework/core/config.hpp"

namespace skinlab::datasets {

struct RepositorySource {
  std::string repository;  ///< "owner/name", or empty for a plain local `path`
  std::string commit;      ///< the 40-hex commit the config was measured at
  std::string path;        ///< inside the repository (or a local directory without one)
  /// `source:` the source's name in the dataset card and in `splits.leave_out_sources`;
  /// empty: label() falls back to the repository or the builder's key.
  std::string name;
  std::string where;        ///< the config node's "file:line: path: ", for messages
  std::string config_file;  ///< the config file, for the fetch_data hint

  /// Reads `source`, `repository`, `commit` and `path` through `f` (`path` required without a
  /// repository) and checks them: owner/name form, a full lowercase commit id, both or neither,
  /// and a relative path without '..' inside a repository.
  static RepositorySource from(config::Fields& f, const config::Node& node);

  /// The name characters and exclusions of this source carry (SourceCharacter::source): `name`,
  /// else the repository ("owner/name"), else `builder`.
  std::string label(const std::string& builder) const;

  /// The directory to read: `path` as it is without a repository; otherwise
  /// `$SKINLAB_DATA_DIR/<owner>/<name>/<path>`. Throws IoError, naming the builder, the
  /// repository and the expected folder with the `scripts/fetch_data` command to run, when the
  /// variable is not set, the repository's folder is missing, or its git checkout is at another
  /// commit than the config names.
  std::filesystem::path root(const std::string& builder) const;
};

}  // namespace skinlab::datasets

#pragma once
/// \file
/// Licence and attribution of a file of an installed Debian package, from the package's
/// `/usr/share/doc/<package>/copyright`, for the dataset card.
///
/// Machine-readable files (DEP-5, https://www.debian.org/doc/packaging-manuals/copyright-format/
/// 1.0/): the last `Files:` paragraph whose glob patterns match the path wins, as the
/// specification says; `*` matches any characters including `/`. Free-form files (older
/// packages such as nexuiz-data) have no per-file paragraphs: the licence is recognised from the
/// GPL's standard notice and the attribution is the line naming the copyright holders.

#include <filesystem>
#include <string>

namespace skinlab::datasets {

struct CopyrightInfo {
  std::string licence;      ///< SPDX-style identifier, e.g. "CC-BY-3.0", "GPL-2.0-or-later"
  std::string attribution;  ///< copyright holders, "; "-separated
};

/// `path` is relative to the upstream source tree (as the Files: patterns are). Throws IoError
/// naming the copyright file when it cannot be read or nothing in it applies to `path`.
CopyrightInfo debian_copyright(const std::filesystem::path& copyright_file,
                               const std::string& path);

/// Glob match of DEP-5 `Files:` patterns: `*` any run of characters (including `/`), `?` one.
bool dep5_match(const std::string& pattern, const std::string& path);

}  // namespace skinlab::datasets

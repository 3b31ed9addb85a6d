#pragma once
/// \file
/// Logging set-up. Library code logs through spdlog's default logger (`spdlog::info(...)`); only
/// the CLI configures sinks.

#include <filesystem>
#include <string>

namespace skinlab::logging {

/// Installs a stderr logger at `level` ("trace", "debug", "info", "warn", "error", "off").
/// An unknown level name is an Error listing the valid ones.
void init(const std::string& level);

/// Also writes every message to `file` (a run's `log.txt`), appending.
void add_file(const std::filesystem::path& file);

}  // namespace skinlab::logging

#pragma once
/// \file
/// Exception types of the library. Library code throws; only the CLI turns an exception into a
/// message and an exit status.

#include <stdexcept>
#include <string>

namespace skinlab {

/// Base of every error skinlab throws on purpose. The message carries its own context
/// (file, key path, vertex or bone), so it can be printed as is.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A configuration file, override or plug-in option is wrong. The message starts with
/// `file:line: key.path:`.
class ConfigError : public Error {
 public:
  using Error::Error;
};

/// A registry lookup or registration failed (unknown key, duplicate key).
class RegistryError : public Error {
 public:
  using Error::Error;
};

/// A file could not be read or written.
class IoError : public Error {
 public:
  using Error::Error;
};

}  // namespace skinlab

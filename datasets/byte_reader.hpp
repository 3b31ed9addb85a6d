#pragma once
/// \file
/// Bounds-checked reading of binary game files (IQM is little-endian, ZYM big-endian). Every
/// read names the file, the element and its byte offset, so a truncated or corrupt file fails
/// with a message such as
///     "snoutx10k.iqm: joint 12 (byte offset 223536): needs 48 bytes, the file has 1000"
/// instead of reading past the end.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace skinlab::datasets {

/// Reads a whole file into memory. Throws IoError naming the file when it cannot be read.
std::string read_binary_file(const std::filesystem::path& file);

class ByteReader {
 public:
  enum class Endian { kLittle, kBig };

  /// `data` must outlive the reader; `source` prefixes every error message.
  ByteReader(std::string_view data, std::string source, Endian endian)
      : data_(data), source_(std::move(source)), endian_(endian) {}

  std::size_t size() const { return data_.size(); }
  const std::string& source() const { return source_; }

  /// Throws IoError unless bytes [offset, offset + count) lie inside the data. `what` names the
  /// element being read (e.g. "vertex 17 position").
  void require(std::size_t offset, std::size_t count, const std::string& what) const;

  std::uint8_t u8(std::size_t offset, const std::string& what) const;
  std::uint16_t u16(std::size_t offset, const std::string& what) const;
  std::uint32_t u32(std::size_t offset, const std::string& what) const;
  std::int32_t i32(std::size_t offset, const std::string& what) const;
  float f32(std::size_t offset, const std::string& what) const;
  /// A string of at most `max_length` bytes ending at the first NUL (fixed-width name fields);
  /// with max_length 0 the string must be NUL-terminated inside the data.
  std::string cstring(std::size_t offset, std::size_t max_length, const std::string& what) const;
  /// The raw bytes [offset, offset + count).
  std::string_view bytes(std::size_t offset, std::size_t count, const std::string& what) const;

  /// Throws IoError "<source>: <what> (byte offset N): <message>".
  [[noreturn]] void fail(std::size_t offset, const std::string& what,
                         const std::string& message) const;

 private:
  std::string_view data_;
  std::string source_;
  Endian endian_;
};

}  // namespace skinlab::datasets

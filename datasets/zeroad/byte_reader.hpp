#pragma once
/// \file
/// Little-endian reading of the engine's packed binary files (CFilePacker/CFileUnpacker in
/// 0 A.D.'s source/ps/FileIo.cpp): a 4-byte magic, a u32 version, a u32 size of the data that
/// follows, then the data. Every read names the file, the byte offset and what was being read.

#include <cstdint>
#include <cstring>
#include <string>

#include "framework/core/error.hpp"

namespace skinlab::datasets::zeroad {

class ByteReader {
 public:
  ByteReader(const std::string& bytes, std::string source)
      : b_(bytes), source_(std::move(source)) {}

  /// Throws Error "source: byte offset N: <message>".
  [[noreturn]] void fail(const std::string& message) const { fail_at(pos_, message); }
  [[noreturn]] void fail_at(std::size_t offset, const std::string& message) const {
    throw Error(source_ + ": byte offset " + std::to_string(offset) + ": " + message);
  }

  void need(std::size_t n, const std::string& what) const {
    if (b_.size() - pos_ < n) {
      fail("truncated while reading " + what + " (needs " + std::to_string(n) + " bytes, " +
           std::to_string(b_.size() - pos_) + " left)");
    }
  }
  /// Checks that `count` elements of `stride` bytes follow (before allocating for them); on
  /// truncation names the first incomplete element ("<what> <i> of <count>") and its offset.
  void need_elements(std::size_t count, std::size_t stride, const std::string& what) const {
    const std::size_t left = b_.size() - pos_;
    if (stride == 0 || left / stride >= count) return;
    const std::size_t i = left / stride;
    fail_at(pos_ + i * stride, "truncated in " + what + " " + std::to_string(i) + " of " +
                                   std::to_string(count) + " (" +
                                   std::to_string(left - i * stride) + " of its " +
                                   std::to_string(stride) + " bytes present)");
  }
  std::uint8_t u8(const std::string& what) {
    need(1, what);
    return static_cast<std::uint8_t>(b_[pos_++]);
  }
  std::uint16_t u16(const std::string& what) {
    need(2, what);
    const auto* p = reinterpret_cast<const unsigned char*>(b_.data() + pos_);
    pos_ += 2;
    return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
  }
  std::uint32_t u32(const std::string& what) {
    need(4, what);
    const auto* p = reinterpret_cast<const unsigned char*>(b_.data() + pos_);
    pos_ += 4;
    return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
           (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
  }
  float f32(const std::string& what) {
    const std::uint32_t bits = u32(what);
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
  }
  /// A u32 length followed by that many bytes (no terminator).
  std::string str(const std::string& what) {
    const std::uint32_t n = u32(what + " length");
    need(n, what);
    std::string s = b_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  /// Reads the file header and checks the magic; returns the version. The declared data size
  /// is checked by finish(), so that a truncated file fails at the element it cuts.
  std::uint32_t header(const char (&magic)[5]) {
    need(12, "the file header");
    if (b_.compare(0, 4, magic) != 0) {
      fail("not a " + std::string(magic) + " file (magic '" + printable(b_.substr(0, 4)) + "')");
    }
    pos_ = 4;
    const std::uint32_t version = u32("the version");
    declared_ = u32("the data size");
    return version;
  }
  /// After the last element: no trailing bytes, and the header's data size was right.
  void finish() const {
    if (pos_ != b_.size()) {
      fail(std::to_string(b_.size() - pos_) + " unexpected trailing bytes after the last element");
    }
    if (static_cast<std::uint64_t>(declared_) != b_.size() - 12) {
      fail_at(8, "header declares " + std::to_string(declared_) + " data bytes, the file has " +
                     std::to_string(b_.size() - 12));
    }
  }
  std::size_t offset() const { return pos_; }
  std::size_t size() const { return b_.size(); }
  const std::string& source() const { return source_; }

 private:
  static std::string printable(const std::string& s) {
    std::string out;
    for (char c : s) out += (c >= 32 && c < 127) ? c : '?';
    return out;
  }
  const std::string& b_;
  std::string source_;
  std::size_t pos_ = 0;
  std::uint32_t declared_ = 0;
};

}  // namespace skinlab::datasets::zeroad

#include "datasets/byte_reader.hpp"

#include <cstring>
#include <fstream>
#include <sstream>

#include "framework/core/error.hpp"

namespace skinlab::datasets {

std::string read_binary_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(file.string() + ": cannot open for reading");
  std::ostringstream out;
  out << in.rdbuf();
  if (in.bad()) throw IoError(file.string() + ": read error");
  return std::move(out).str();
}

void ByteReader::fail(std::size_t offset, const std::string& what,
                      const std::string& message) const {
  throw IoError(source_ + ": " + what + " (byte offset " + std::to_string(offset) +
                "): " + message);
}

void ByteReader::require(std::size_t offset, std::size_t count, const std::string& what) const {
  if (offset > data_.size() || count > data_.size() - offset) {
    fail(offset, what,
         "needs " + std::to_string(count) + " bytes, the file has " + std::to_string(data_.size()) +
             " (truncated or corrupt)");
  }
}

namespace {
std::uint32_t load(std::string_view data, std::size_t offset, int bytes, bool big) {
  std::uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) {
    const auto b = static_cast<std::uint32_t>(static_cast<unsigned char>(data[offset + i]));
    v |= big ? b << (8 * (bytes - 1 - i)) : b << (8 * i);
  }
  return v;
}
}  // namespace

std::uint8_t ByteReader::u8(std::size_t offset, const std::string& what) const {
  require(offset, 1, what);
  return static_cast<std::uint8_t>(data_[offset]);
}

std::uint16_t ByteReader::u16(std::size_t offset, const std::string& what) const {
  require(offset, 2, what);
  return static_cast<std::uint16_t>(load(data_, offset, 2, endian_ == Endian::kBig));
}

std::uint32_t ByteReader::u32(std::size_t offset, const std::string& what) const {
  require(offset, 4, what);
  return load(data_, offset, 4, endian_ == Endian::kBig);
}

std::int32_t ByteReader::i32(std::size_t offset, const std::string& what) const {
  const std::uint32_t u = u32(offset, what);
  std::int32_t i;
  std::memcpy(&i, &u, 4);
  return i;
}

float ByteReader::f32(std::size_t offset, const std::string& what) const {
  const std::uint32_t u = u32(offset, what);
  float f;
  std::memcpy(&f, &u, 4);  // IEEE-754 binary32, as both formats store floats
  return f;
}

std::string ByteReader::cstring(std::size_t offset, std::size_t max_length,
                                const std::string& what) const {
  if (offset >= data_.size()) require(offset, 1, what);
  if (max_length > 0) {
    require(offset, max_length, what);
    const std::string_view field = data_.substr(offset, max_length);
    return std::string(field.substr(0, field.find('\0')));
  }
  const std::size_t end = data_.find('\0', offset);
  if (end == std::string_view::npos) fail(offset, what, "string is not NUL-terminated");
  return std::string(data_.substr(offset, end - offset));
}

std::string_view ByteReader::bytes(std::size_t offset, std::size_t count,
                                   const std::string& what) const {
  require(offset, count, what);
  return data_.substr(offset, count);
}

}  // namespace skinlab::datasets

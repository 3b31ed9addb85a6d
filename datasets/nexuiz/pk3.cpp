#include "datasets/nexuiz/pk3.hpp"

#include <zlib.h>

#include <algorithm>
#include <fstream>

#include "datasets/byte_reader.hpp"
#include "framework/core/error.hpp"

namespace skinlab::datasets::nexuiz {
namespace {

constexpr std::uint32_t kEndOfCentralDirectory = 0x06054b50, kCentralHeader = 0x02014b50,
                        kLocalHeader = 0x04034b50;
constexpr std::size_t kEocdSize = 22, kCentralSize = 46, kLocalSize = 30;
constexpr std::size_t kMaxComment = 0xffff;

std::string read_range(const std::filesystem::path& file, std::uint64_t offset, std::size_t count) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(file.string() + ": cannot open for reading");
  in.seekg(static_cast<std::streamoff>(offset));
  std::string out(count, '\0');
  in.read(out.data(), static_cast<std::streamsize>(count));
  out.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return out;
}

}  // namespace

ZipArchive::ZipArchive(std::filesystem::path file) : file_(std::move(file)) {
  std::error_code ec;
  size_ = std::filesystem::file_size(file_, ec);
  if (ec) throw IoError(file_.string() + ": cannot read the archive (" + ec.message() + ")");
  const std::string source = file_.string();
  if (size_ < kEocdSize) {
    throw IoError(source + ": " + std::to_string(size_) + " bytes is too short for a zip archive");
  }
  // The end-of-central-directory record is the last 22 bytes plus a comment of up to 64 KiB.
  const std::uint64_t tail_start =
      size_ > kEocdSize + kMaxComment ? size_ - kEocdSize - kMaxComment : 0;
  const std::string tail =
      read_range(file_, tail_start, static_cast<std::size_t>(size_ - tail_start));
  const ByteReader t(tail, source, ByteReader::Endian::kLittle);
  std::size_t eocd = std::string::npos;
  for (std::size_t i = tail.size() - kEocdSize + 1; i-- > 0;) {
    if (t.u32(i, "end of central directory") == kEndOfCentralDirectory) {
      eocd = i;
      break;
    }
  }
  if (eocd == std::string::npos) {
    throw IoError(source + ": not a zip archive (no end-of-central-directory record)");
  }
  const std::string where =
      "end of central directory at archive offset " + std::to_string(tail_start + eocd);
  if (t.u16(eocd + 4, where) != 0 || t.u16(eocd + 6, where) != 0) {
    throw IoError(source + ": " + where + ": multi-disk archives are not supported");
  }
  const std::uint16_t count = t.u16(eocd + 10, where);
  const std::uint32_t cd_size = t.u32(eocd + 12, where), cd_offset = t.u32(eocd + 16, where);
  if (count == 0xffff || cd_size == 0xffffffff || cd_offset == 0xffffffff) {
    throw IoError(source + ": " + where + ": ZIP64 archives are not supported");
  }
  if (std::uint64_t(cd_offset) + cd_size > size_) {
    throw IoError(source + ": " + where + ": central directory [" + std::to_string(cd_offset) +
                  ", +" + std::to_string(cd_size) + ") lies beyond the archive's " +
                  std::to_string(size_) + " bytes (truncated)");
  }
  const std::string cd = read_range(file_, cd_offset, cd_size);
  // Offsets in messages are archive offsets: the reader's source says so.
  const ByteReader r(cd, source + " (central directory at " + std::to_string(cd_offset) + ")",
                     ByteReader::Endian::kLittle);
  std::size_t o = 0;
  for (std::uint16_t i = 0; i < count; ++i) {
    const std::string what = "central directory entry " + std::to_string(i);
    if (r.u32(o, what) != kCentralHeader) r.fail(o, what, "bad signature");
    r.require(o, kCentralSize, what);
    Entry e;
    e.flags = r.u16(o + 8, what);
    e.method = r.u16(o + 10, what);
    e.crc32 = r.u32(o + 16, what);
    e.compressed_size = r.u32(o + 20, what);
    e.size = r.u32(o + 24, what);
    const std::uint16_t name_len = r.u16(o + 28, what), extra_len = r.u16(o + 30, what),
                        comment_len = r.u16(o + 32, what);
    e.local_header = r.u32(o + 42, what);
    e.name = std::string(r.bytes(o + kCentralSize, name_len, what + " name"));
    o += kCentralSize + name_len + extra_len + comment_len;
    entries_.push_back(std::move(e));
  }
}

const ZipArchive::Entry* ZipArchive::find(const std::string& name) const {
  for (const auto& e : entries_) {
    if (e.name == name) return &e;
  }
  return nullptr;
}

std::string ZipArchive::read(const Entry& e) const {
  const std::string what = file_.string() + ":" + e.name;
  if (e.flags & 1) throw IoError(what + ": encrypted members are not supported");
  if (e.method != 0 && e.method != 8) {
    throw IoError(what + ": compression method " + std::to_string(e.method) +
                  " is not supported (only stored and deflate)");
  }
  const std::string header = read_range(file_, e.local_header, kLocalSize);
  const ByteReader h(
      header, what + " (local header at archive offset " + std::to_string(e.local_header) + ")",
      ByteReader::Endian::kLittle);
  if (h.u32(0, "signature") != kLocalHeader) h.fail(0, "signature", "not a local file header");
  const std::uint64_t data_offset = std::uint64_t(e.local_header) + kLocalSize +
                                    h.u16(26, "name length") + h.u16(28, "extra length");
  if (data_offset + e.compressed_size > size_) {
    throw IoError(what + ": data at archive offset " + std::to_string(data_offset) + " (+" +
                  std::to_string(e.compressed_size) + " bytes) lies beyond the archive's " +
                  std::to_string(size_) + " bytes (truncated)");
  }
  std::string data = read_range(file_, data_offset, e.compressed_size);
  std::string out;
  if (e.method == 0) {
    out = std::move(data);
  } else {
    // Deflate expands at most 1032:1 (zlib's technical notes), so a larger size is corrupt;
    // checked before the output buffer is allocated.
    if (e.size > std::uint64_t(e.compressed_size) * 1032 + 1032) {
      throw IoError(what + ": uncompressed size " + std::to_string(e.size) +
                    " is more than deflate can produce from " + std::to_string(e.compressed_size) +
                    " bytes (corrupt size)");
    }
    out.resize(e.size);
    z_stream z{};
    if (inflateInit2(&z, -MAX_WBITS) != Z_OK) throw IoError(what + ": inflateInit2 failed");
    z.next_in = reinterpret_cast<Bytef*>(data.data());
    z.avail_in = static_cast<uInt>(data.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = static_cast<uInt>(out.size());
    const int status = inflate(&z, Z_FINISH);
    const std::uint64_t produced = z.total_out;
    const std::string message = z.msg ? z.msg : "";
    inflateEnd(&z);
    if (status != Z_STREAM_END || produced != e.size) {
      throw IoError(what + ": corrupt deflate data at archive offset " +
                    std::to_string(data_offset) + " (zlib status " + std::to_string(status) +
                    (message.empty() ? "" : ": " + message) + "; " + std::to_string(produced) +
                    " of " + std::to_string(e.size) + " bytes)");
    }
  }
  if (out.size() != e.size) throw IoError(what + ": size mismatch");
  const auto crc = static_cast<std::uint32_t>(crc32(crc32(0L, Z_NULL, 0),
                                                    reinterpret_cast<const Bytef*>(out.data()),
                                                    static_cast<uInt>(out.size())));
  if (crc != e.crc32) throw IoError(what + ": CRC-32 mismatch (corrupt member)");
  return out;
}

}  // namespace skinlab::datasets::nexuiz

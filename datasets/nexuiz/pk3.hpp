#pragma once
/// \file
/// Minimal reader of zip archives (Quake-family `.pk3` files are plain zips): the central
/// directory and stored or deflated members, as specified in PKWARE's APPNOTE.TXT (sections 4.3.7
/// local file header, 4.3.12 central directory header, 4.3.16 end of central directory record).
/// Members are read on demand from the file (data.pk3 is 278 MB); each is inflated with zlib and
/// checked against its CRC-32. Not supported (reported as errors): ZIP64, encryption, methods
/// other than 0 (stored) and 8 (deflate), multi-disk archives.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace skinlab::datasets::nexuiz {

class ZipArchive {
 public:
  struct Entry {
    std::string name;          ///< path inside the archive, '/'-separated
    std::uint16_t method = 0;  ///< 0 stored, 8 deflate
    std::uint16_t flags = 0;   ///< general purpose bit flag (bit 0: encrypted)
    std::uint32_t crc32 = 0;
    std::uint32_t compressed_size = 0;
    std::uint32_t size = 0;          ///< uncompressed
    std::uint32_t local_header = 0;  ///< offset of the local file header
  };

  /// Reads the central directory. Throws IoError naming the archive and the byte offset for a
  /// file that is not a zip, is truncated, or uses an unsupported feature.
  explicit ZipArchive(std::filesystem::path file);

  const std::vector<Entry>& entries() const { return entries_; }
  /// The entry named `name`, or nullptr.
  const Entry* find(const std::string& name) const;
  /// The uncompressed bytes of `entry`. Throws IoError naming "<archive>:<member>" for a corrupt
  /// or unsupported member or a CRC mismatch.
  std::string read(const Entry& entry) const;
  const std::filesystem::path& path() const { return file_; }

 private:
  std::filesystem::path file_;
  std::uint64_t size_ = 0;
  std::vector<Entry> entries_;
};

}  // namespace skinlab::datasets::nexuiz

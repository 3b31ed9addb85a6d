#pragma once
/// \file
/// Reader of OpenClonk's C4Group files: the archives its game data is packed in (`.ocd`
/// definitions, `.ocf` scenario folders, `.ocs` scenarios, `.ocg` groups). Format reference:
/// OpenClonk's src/c4group/C4Group.h and C4Group.cpp (C4GroupHeader, C4GroupEntryCore,
/// MemScramble, C4Group::OpenRealGrpFile); checked against Debian's openclonk-data 8.1.
///
/// A packed group file is a gzip stream (RFC 1952) whose magic bytes 1F 8B are stored as
/// 1E 8C (the original magic is accepted too). Its decompressed bytes are an unpacked group:
///
///     offset 0    C4GroupHeader, 204 bytes, "memscrambled": every byte XOR 0xED, then the
///                 bytes at i and i + 2 swapped for i = 0, 3, 6, … (i + 2 < 204). Plain:
///                   char    id[28]    "RedWolf Design GrpFolder", NUL-padded
///                   int32   Ver1, Ver2   1 and ≤ 2 (the engine's check)
///                   int32   Entries
///                   char    reserved[164]
///     offset 204  Entries × C4GroupEntryCore, 316 bytes each, not scrambled:
///                   char    FileName[260]   NUL-terminated
///                   int32   Packed          (unused by readers)
///                   int32   ChildGroup      non-zero: the entry is a group
///                   int32   Size
///                   int32   reserved
///                   int32   Offset          from the end of the entry cores
///                   int32   reserved (time), char HasCRC, uint32 CRC, char Executable,
///                   char    reserved[26]
///     then        the entries' bytes, entry k at 204 + 316·Entries + Offset_k.
///
/// All integers are little-endian. A child group's bytes are an unpacked group (header, cores,
/// data; no gzip of its own), so nested definitions (`Objects.ocd/Animals.ocd/Wipf.ocd`) are
/// read in place inside the one decompressed buffer.
///
/// Everything is bounds-checked, and bad input throws IoError naming the group file, the path
/// of the (child) group inside it, the entry and the byte offset; never reads out of bounds:
/// the decompressed size is capped (`max_size`), child groups nest at most kMaxDepth deep, an
/// entry count must fit the data, an entry's name must be a plain file name, its bytes must lie
/// inside its group's data and not overlap another entry's (so nesting cannot multiply entries).

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace skinlab::datasets::openclonk {

class C4Group {
 public:
  struct Entry {
    std::string path;         ///< inside the group, '/'-separated: "Animals.ocd/Wipf.ocd/Graphics.mesh"
    std::size_t offset = 0;   ///< of its bytes in the decompressed group
    std::size_t size = 0;
    bool group = false;       ///< a child group (its entries follow it in entries())
  };

  static constexpr std::size_t kDefaultMaxSize = std::size_t{1} << 30;  ///< 1 GiB decompressed
  static constexpr int kMaxDepth = 16;  ///< nested child groups (OpenClonk's data: 4)

  /// Reads a packed group file: restores the gzip magic, inflates at most `max_size` bytes and
  /// lists every entry recursively. Throws IoError naming the file when it cannot be read, is
  /// not a packed group, is truncated or corrupt, or inflates to more than `max_size` bytes.
  static C4Group open(const std::filesystem::path& file, std::size_t max_size = kDefaultMaxSize);

  /// Lists an unpacked group (the decompressed bytes of a packed one); `name` (e.g. the file's
  /// name) prefixes every error message.
  static C4Group parse(std::string data, std::string name);

  const std::string& name() const { return name_; }
  /// Every entry, depth-first in stored order: a child group, then its entries.
  const std::vector<Entry>& entries() const { return entries_; }
  /// The entry at `path`, or nullptr.
  const Entry* find(const std::string& path) const;
  /// An entry's bytes (a child group's are an unpacked group).
  std::string read(const Entry& entry) const;

 private:
  void list(std::size_t start, std::size_t size, const std::string& prefix, int depth);

  std::string name_;
  std::string data_;
  std::vector<Entry> entries_;
};

/// The decompressed bytes of a packed group file's contents `packed` (gzip with magic 1E 8C or
/// 1F 8B); `name` prefixes errors. Throws IoError for a wrong magic, corrupt or truncated data,
/// or more than `max_size` bytes.
std::string inflate_c4group(std::string_view packed, const std::string& name,
                            std::size_t max_size = C4Group::kDefaultMaxSize);

}  // namespace skinlab::datasets::openclonk

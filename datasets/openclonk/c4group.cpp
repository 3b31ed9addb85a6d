#include "datasets/openclonk/c4group.hpp"

#include <zlib.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <set>

#include "datasets/byte_reader.hpp"
#include "framework/core/error.hpp"

namespace skinlab::datasets::openclonk {
namespace {

constexpr std::size_t kHeaderSize = 204, kCoreSize = 316, kNameSize = 260;
constexpr char kGroupId[] = "RedWolf Design GrpFolder";

/// OpenClonk's MemScramble (its own inverse: the XOR and the swaps commute).
std::string memscramble(std::string_view bytes) {
  std::string out(bytes);
  for (char& c : out) c = static_cast<char>(static_cast<unsigned char>(c) ^ 0xED);
  for (std::size_t i = 0; i + 2 < out.size(); i += 3) std::swap(out[i], out[i + 2]);
  return out;
}

}  // namespace

std::string inflate_c4group(std::string_view packed, const std::string& name,
                            std::size_t max_size) {
  if (packed.size() < 2) {
    throw IoError(name + ": " + std::to_string(packed.size()) +
                  " bytes is too short for a packed C4Group");
  }
  const auto b0 = static_cast<unsigned char>(packed[0]), b1 = static_cast<unsigned char>(packed[1]);
  if (!((b0 == 0x1E && b1 == 0x8C) || (b0 == 0x1F && b1 == 0x8B))) {
    char magic[16];
    std::snprintf(magic, sizeof magic, "%02X %02X", b0, b1);
    throw IoError(name + ": not a packed C4Group (magic bytes " + magic +
                  ", expected 1E 8C: gzip with OpenClonk's altered magic)");
  }
  if (packed.size() > UINT_MAX) {
    throw IoError(name + ": " + std::to_string(packed.size()) + " bytes is more than zlib reads at once");
  }
  std::string in(packed);
  in[0] = '\x1f';
  in[1] = '\x8b';
  z_stream z{};
  if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK) throw IoError(name + ": inflateInit2 failed");
  z.next_in = reinterpret_cast<Bytef*>(in.data());
  z.avail_in = static_cast<uInt>(in.size());
  std::string out;
  int status = Z_OK;
  while (status == Z_OK) {
    if (out.size() >= max_size) break;
    const std::size_t chunk = std::min<std::size_t>(max_size - out.size(), std::size_t{1} << 22);
    const std::size_t before = out.size();
    out.resize(before + chunk);
    z.next_out = reinterpret_cast<Bytef*>(out.data() + before);
    z.avail_out = static_cast<uInt>(chunk);
    status = inflate(&z, Z_NO_FLUSH);
    out.resize(before + chunk - z.avail_out);
    if (status == Z_BUF_ERROR && z.avail_in == 0) break;  // input ends inside the stream
  }
  const std::string message = z.msg ? z.msg : "";
  const std::size_t consumed = z.total_in;
  inflateEnd(&z);
  if (status == Z_STREAM_END) return out;
  if (status == Z_OK || (status == Z_BUF_ERROR && out.size() >= max_size)) {
    throw IoError(name + ": decompresses to more than " + std::to_string(max_size) +
                  " bytes (the reader's limit)");
  }
  throw IoError(name + ": " +
                (status == Z_BUF_ERROR ? std::string("truncated gzip stream")
                                       : "corrupt gzip stream (zlib status " +
                                             std::to_string(status) +
                                             (message.empty() ? "" : ": " + message) + ")") +
                " after " + std::to_string(consumed) + " of " + std::to_string(packed.size()) +
                " bytes");
}

C4Group C4Group::open(const std::filesystem::path& file, std::size_t max_size) {
  const std::string name = file.filename().string();
  return parse(inflate_c4group(read_binary_file(file), name, max_size), name);
}

C4Group C4Group::parse(std::string data, std::string name) {
  C4Group g;
  g.name_ = std::move(name);
  g.data_ = std::move(data);
  g.list(0, g.data_.size(), "", 0);
  return g;
}

void C4Group::list(std::size_t start, std::size_t size, const std::string& prefix, int depth) {
  const std::string group = prefix.empty() ? name_ : name_ + "/" + prefix.substr(0, prefix.size() - 1);
  if (depth > kMaxDepth) {
    throw IoError(group + ": child groups nested more than " + std::to_string(kMaxDepth) +
                  " deep (a group containing itself?)");
  }
  // Offsets in messages are relative to this (child) group's first byte.
  const ByteReader r(std::string_view(data_).substr(start, size), group, ByteReader::Endian::kLittle);
  const std::string header = memscramble(r.bytes(0, kHeaderSize, "group header"));
  const ByteReader h(header, group, ByteReader::Endian::kLittle);
  const std::string id = h.cstring(0, 28, "group header id");
  if (id != kGroupId) {
    r.fail(0, "group header",
           "not a C4Group (unscrambled id '" + id.substr(0, 28) + "', expected '" + kGroupId + "')");
  }
  const std::int32_t ver1 = h.i32(28, "group header version"), ver2 = h.i32(32, "group header version");
  if (ver1 != 1 || ver2 > 2) {
    r.fail(28, "group header", "unsupported version " + std::to_string(ver1) + "." +
                                   std::to_string(ver2) + " (read: 1.0 to 1.2)");
  }
  const std::int32_t count = h.i32(36, "group header entry count");
  if (count < 0 || static_cast<std::size_t>(count) > (size - kHeaderSize) / kCoreSize) {
    r.fail(36, "group header",
           "entry count " + std::to_string(count) + " does not fit the group's " +
               std::to_string(size) + " bytes (" + std::to_string(kCoreSize) + " per entry)");
  }
  const std::size_t data_start = kHeaderSize + static_cast<std::size_t>(count) * kCoreSize;
  const std::size_t data_size = size - data_start;
  struct Span {
    std::size_t offset, size;
    int index;
  };
  std::vector<Span> spans;
  std::set<std::string> names;
  std::vector<Entry> listed;
  for (int k = 0; k < count; ++k) {
    const std::size_t core = kHeaderSize + static_cast<std::size_t>(k) * kCoreSize;
    const std::string what = "entry " + std::to_string(k);
    const std::string file = r.cstring(core, kNameSize, what + " name");
    if (file.size() >= kNameSize) r.fail(core, what, "name without its terminating NUL");
    if (file.empty() || file == "." || file == ".." ||
        file.find_first_of(std::string("/\\", 2)) != std::string::npos) {
      r.fail(core, what, "'" + file + "' is not a plain file name");
    }
    const std::string named = what + " '" + file + "'";
    if (!names.insert(file).second) r.fail(core, named, "a second entry of that name");
    const std::int32_t child = r.i32(core + kNameSize + 4, named + " child-group flag");
    const std::int32_t entry_size = r.i32(core + kNameSize + 8, named + " size");
    const std::int32_t offset = r.i32(core + kNameSize + 16, named + " offset");
    if (entry_size < 0 || offset < 0 ||
        static_cast<std::size_t>(offset) > data_size ||
        static_cast<std::size_t>(entry_size) > data_size - static_cast<std::size_t>(offset)) {
      r.fail(core, named,
             "overruns the group (offset " + std::to_string(offset) + ", size " +
                 std::to_string(entry_size) + "; the group has " + std::to_string(data_size) +
                 " bytes of entry data after its " + std::to_string(count) + " entry cores)");
    }
    Entry e;
    e.path = prefix + file;
    e.offset = start + data_start + static_cast<std::size_t>(offset);
    e.size = static_cast<std::size_t>(entry_size);
    e.group = child != 0;
    spans.push_back({static_cast<std::size_t>(offset), e.size, k});
    listed.push_back(e);
  }
  std::sort(spans.begin(), spans.end(), [](const Span& a, const Span& b) {
    return a.offset != b.offset ? a.offset < b.offset : a.index < b.index;
  });
  const Span* reach = nullptr;  // the non-empty span ending last so far
  for (const Span& b : spans) {
    if (b.size == 0) continue;
    if (reach && reach->offset + reach->size > b.offset) {
      r.fail(kHeaderSize + static_cast<std::size_t>(b.index) * kCoreSize,
             "entry " + std::to_string(b.index) + " '" + listed[b.index].path.substr(prefix.size()) + "'",
             "its bytes [" + std::to_string(b.offset) + ", +" + std::to_string(b.size) +
                 ") overlap those of entry " + std::to_string(reach->index) + " [" +
                 std::to_string(reach->offset) + ", +" + std::to_string(reach->size) + ")");
    }
    if (!reach || b.offset + b.size > reach->offset + reach->size) reach = &b;
  }
  for (const Entry& e : listed) {
    entries_.push_back(e);
    if (e.group) list(e.offset, e.size, e.path + "/", depth + 1);
  }
}

const C4Group::Entry* C4Group::find(const std::string& path) const {
  for (const Entry& e : entries_) {
    if (e.path == path) return &e;
  }
  return nullptr;
}

std::string C4Group::read(const Entry& entry) const {
  if (entry.offset > data_.size() || entry.size > data_.size() - entry.offset) {
    throw IoError(name_ + "/" + entry.path + ": not an entry of this group");
  }
  return data_.substr(entry.offset, entry.size);
}

}  // namespace skinlab::datasets::openclonk

#pragma once
// A zip archive written in memory, for the tests of the pk3 reader (datasets/nexuiz/pk3.hpp).

#include <zlib.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

namespace skinlab::testing {

/// A zip archive of (name, bytes, deflate?) members, written as APPNOTE.TXT says (the pk3
/// tests' archives and the pk3 fuzz target's seeds: no zip is committed under datasets/).
inline std::string make_zip(const std::vector<std::tuple<std::string, std::string, bool>>& members) {
  std::string out, central;
  auto u16 = [](std::string& s, unsigned v) { s += char(v & 0xff), s += char((v >> 8) & 0xff); };
  auto u32 = [&](std::string& s, std::uint32_t v) { u16(s, v & 0xffff), u16(s, v >> 16); };
  for (const auto& [name, data, deflate] : members) {
    std::string stored = data;
    if (deflate) {
      z_stream z{};
      deflateInit2(&z, 9, Z_DEFLATED, -MAX_WBITS, 8, Z_DEFAULT_STRATEGY);
      stored.resize(deflateBound(&z, data.size()));
      z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
      z.avail_in = static_cast<uInt>(data.size());
      z.next_out = reinterpret_cast<Bytef*>(stored.data());
      z.avail_out = static_cast<uInt>(stored.size());
      if (::deflate(&z, Z_FINISH) != Z_STREAM_END) throw std::runtime_error("deflate failed");
      stored.resize(z.total_out);
      deflateEnd(&z);
    }
    const auto crc = static_cast<std::uint32_t>(
        crc32(0, reinterpret_cast<const Bytef*>(data.data()), static_cast<uInt>(data.size())));
    const auto offset = static_cast<std::uint32_t>(out.size());
    std::string common;
    u16(common, 20), u16(common, 0), u16(common, deflate ? 8 : 0), u16(common, 0), u16(common, 0);
    u32(common, crc), u32(common, stored.size()), u32(common, data.size());
    u16(common, name.size()), u16(common, 0);
    u32(out, 0x04034b50), out += common, out += name, out += stored;
    u32(central, 0x02014b50), u16(central, 20), central += common;
    u16(central, 0), u16(central, 0), u16(central, 0), u32(central, 0), u32(central, offset);
    central += name;
  }
  const auto cd_offset = static_cast<std::uint32_t>(out.size());
  out += central;
  u32(out, 0x06054b50), u16(out, 0), u16(out, 0), u16(out, members.size()),
      u16(out, members.size());
  u32(out, central.size()), u32(out, cd_offset), u16(out, 0);
  return out;
}

}  // namespace skinlab::testing

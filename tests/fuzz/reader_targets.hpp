#pragma once
// The binary and XML game-file readers of datasets/ as fuzz targets: for each, its name (also
// the directory of its regression inputs, tests/data/fuzz_regressions/readers/<name>/), its seed files
// (small files committed under datasets/*/bundled/) and a `parse(bytes, file)` that runs the
// reader, and what a builder computes right after it, on one input. A call returns when the
// input is accepted and throws skinlab::Error when it is rejected; anything else is a finding.
// Used by readers_fuzz_test.cpp (label long) and fuzz_regressions_test.cpp (label fast).

#include <zlib.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "datasets/cube2/iqm.hpp"
#include "datasets/nexuiz/pk3.hpp"
#include "datasets/nexuiz/zym.hpp"
#include "datasets/ogre/ogre_file.hpp"
#include "datasets/openclonk/c4group.hpp"
#include "datasets/zeroad/read_pmd.hpp"
#include "datasets/zeroad/read_psa.hpp"
#include "datasets/zeroad/read_skeletons.hpp"
#include "tests/fuzz/fuzz_harness.hpp"

namespace skinlab::fuzz {

struct ReaderTarget {
  std::string name;
  bool binary = true;  ///< mutated with mutate_binary (else mutate, for text)
  std::function<std::vector<std::string>()> seeds;
  std::function<void(const std::string& bytes, const fs::path& file)> parse;
};

inline std::string bundled(const std::string& path) {
  return read_bytes(fs::path(SKINLAB_SOURCE_DIR) / "datasets" / path);
}

/// A zip archive of (name, bytes, deflate?) members, written as APPNOTE.TXT says (the pk3
/// target's seed: no zip is committed under datasets/).
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

inline std::vector<ReaderTarget> reader_targets() {
  using namespace datasets;
  const std::string art = "zeroad/bundled/art/";
  std::vector<ReaderTarget> t;
  t.push_back({"pmd", true,
               [=] {
                 return std::vector<std::string>{
                     bundled(art + "meshes/skeletal/bird_circle.dae.cached.pmd"),
                     bundled(art + "meshes/skeletal/walrus.dae.cached.pmd")};
               },
               [](const std::string& bytes, const fs::path&) { zeroad::read_pmd(bytes, "fuzz.pmd"); }});
  t.push_back({"psa", true,
               [=] {
                 return std::vector<std::string>{
                     bundled(art + "animation/other/hawk_flight.dae.cached.psa"),
                     bundled(art + "animation/other/hawk_glide.dae.cached.psa")};
               },
               [](const std::string& bytes, const fs::path&) { zeroad::read_psa(bytes, "fuzz.psa"); }});
  t.push_back({"skeleton_xml", false,
               [=] {
                 return std::vector<std::string>{bundled(art + "skeletons/han_ram.xml"),
                                                 bundled(art + "skeletons/bow.xml"),
                                                 bundled(art + "skeletons/hawk.xml"),
                                                 bundled(art + "skeletons/chicken.xml")};
               },
               [](const std::string& bytes, const fs::path&) {
                 zeroad::read_skeletons(bytes, "fuzz.xml");
               }});
  t.push_back({"iqm", true,
               [] {
                 return std::vector<std::string>{bundled("cube2/bundled/snoutx10k/forward.md5anim.iqm"),
                                                 bundled("cube2/bundled/snoutx10k/snoutx10k.iqm")};
               },
               [](const std::string& bytes, const fs::path&) {
                 const cube2::IqmFile iqm = cube2::read_iqm(bytes, "fuzz.iqm");
                 std::vector<std::string> names;
                 for (std::size_t p = 0; p < iqm.pose_parents.size(); ++p) {
                   names.push_back("pose " + std::to_string(p));
                 }
                 for (const auto& clip : iqm.clips) {
                   cube2::global_frames(clip, iqm.pose_parents, names, "fuzz.iqm");
                 }
               }});
  t.push_back({"zym", true,
               [] { return std::vector<std::string>{bundled("nexuiz/bundled/models/player/marine.zym")}; },
               [](const std::string& bytes, const fs::path&) { nexuiz::read_zym(bytes, "fuzz.zym"); }});
  t.push_back({"pk3", true,
               [] {
                 std::string text;
                 for (int i = 0; i < 200; ++i) text += "line " + std::to_string(i) + " of a member\n";
                 return std::vector<std::string>{
                     make_zip({{"models/player/a.txt", text, true}, {"b.txt", "stored", false}}),
                     make_zip({{"models/player/marine.txt",
                                bundled("nexuiz/bundled/models/player/marine.txt"), true}})};
               },
               [](const std::string&, const fs::path& file) {
                 const nexuiz::ZipArchive zip(file);
                 for (const auto& entry : zip.entries()) zip.read(entry);
               }});
  t.push_back({"ogre_mesh", true,
               [] {
                 return std::vector<std::string>{bundled("ogre/bundled/opendungeons/Knight.mesh"),
                                                 bundled("ogre/bundled/sumwars/fire_slug.mesh")};
               },
               [](const std::string& bytes, const fs::path&) { ogre::parse_mesh(bytes, "fuzz.mesh"); }});
  t.push_back({"ogre_skeleton", true,
               [] {
                 return std::vector<std::string>{bundled("ogre/bundled/sumwars/fire_slug.skeleton"),
                                                 bundled("ogre/bundled/opendungeons/Knight.skeleton")};
               },
               [](const std::string& bytes, const fs::path&) {
                 const ogre::OgreSkeleton s = ogre::parse_skeleton(bytes, "fuzz.skeleton");
                 ogre::derive_bind_pose(s);
                 for (const auto& a : s.animations) ogre::sample_animation(s, a, 0.5 * a.length);
               }});
  // Packed (gzip with the altered magic: mutations mostly meet zlib's checks) and unpacked
  // (the group structure our reader parses); a packed input is inflated first, as
  // C4Group::open does.
  t.push_back({"c4group", true,
               [] {
                 const std::string packed = bundled("openclonk/bundled/Chippie.ocd");
                 return std::vector<std::string>{
                     packed, openclonk::inflate_c4group(packed, "Chippie.ocd")};
               },
               [](const std::string& bytes, const fs::path&) {
                 const bool packed = bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1E &&
                                     static_cast<unsigned char>(bytes[1]) == 0x8C;
                 const auto g = openclonk::C4Group::parse(
                     packed ? openclonk::inflate_c4group(bytes, "fuzz.ocd") : bytes, "fuzz.ocd");
                 for (const auto& e : g.entries()) g.read(e);
               }});
  return t;
}

}  // namespace skinlab::fuzz

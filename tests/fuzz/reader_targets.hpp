#pragma once
// The binary and XML game-file readers of datasets/ as fuzz targets: for each, its name (also
// the directory of its regression inputs, tests/data/fuzz_regressions/readers/<name>/), its seed files
// (small files committed under datasets/*/bundled/) and a `parse(bytes, file)` that runs the
// reader, and what a builder computes right after it, on one input. A call returns when the
// input is accepted and throws skinlab::Error when it is rejected; anything else is a finding.
// Used by readers_fuzz_test.cpp (label long) and fuzz_regressions_test.cpp (label fast).

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
#include "tests/datasets/zip_writer.hpp"
#include "tests/fuzz/fuzz_harness.hpp"

namespace skinlab::fuzz {

using testing::make_zip;

struct ReaderTarget {
  std::string name;
  bool binary = true;  ///< mutated with mutate_binary (else mutate, for text)
  std::function<std::vector<std::string>()> seeds;
  std::function<void(const std::string& bytes, const fs::path& file)> parse;
};

inline std::string bundled(const std::string& path) {
  return read_bytes(fs::path(SKINLAB_SOURCE_DIR) / "datasets" / path);
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

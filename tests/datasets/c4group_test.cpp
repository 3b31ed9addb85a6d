// The C4Group reader (datasets/openclonk/c4group.hpp) on the bundled real group Chippie.ocd
// (openclonk-data, CC-BY-3.0; datasets/openclonk/bundled/LICENSE.md) and on groups written here
// by the documented layout, intact and damaged.

#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <random>

#include "datasets/byte_reader.hpp"
#include "datasets/ogre/ogre_file.hpp"
#include "datasets/openclonk/c4group.hpp"
#include "framework/core/error.hpp"
#include "tests/test_util.hpp"

namespace skinlab::datasets {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using openclonk::C4Group;

const std::string kChippie = SKINLAB_SOURCE_DIR "/datasets/openclonk/bundled/Chippie.ocd";

/// One entry of a group written by make_group: a file, or a child group's bytes.
struct Item {
  std::string name;
  std::string bytes;
  bool group = false;
};

void put_i32(std::string& s, std::size_t at, std::int32_t v) {
  for (int i = 0; i < 4; ++i) s[at + i] = static_cast<char>((static_cast<std::uint32_t>(v) >> (8 * i)) & 0xff);
}

/// An unpacked group as OpenClonk writes one: the scrambled 204-byte header, one 316-byte
/// core per entry, then the entries' bytes in order.
std::string make_group(const std::vector<Item>& items) {
  std::string header(204, '\0');
  const std::string id = "RedWolf Design GrpFolder";
  std::copy(id.begin(), id.end(), header.begin());
  put_i32(header, 28, 1);
  put_i32(header, 32, 2);
  put_i32(header, 36, static_cast<std::int32_t>(items.size()));
  for (std::size_t i = 0; i + 2 < header.size(); i += 3) std::swap(header[i], header[i + 2]);
  for (char& c : header) c = static_cast<char>(c ^ 0xED);
  std::string cores, data;
  for (const Item& item : items) {
    std::string core(316, '\0');
    std::copy(item.name.begin(), item.name.end(), core.begin());
    put_i32(core, 264, item.group ? 1 : 0);
    put_i32(core, 268, static_cast<std::int32_t>(item.bytes.size()));
    put_i32(core, 276, static_cast<std::int32_t>(data.size()));
    cores += core;
    data += item.bytes;
  }
  return header + cores + data;
}

/// A packed group file: gzip (RFC 1952) of `group` in stored deflate blocks, magic 1E 8C.
std::string pack(const std::string& group) {
  std::string out = {'\x1e', '\x8c', 8, 0, 0, 0, 0, 0, 0, 3};
  for (std::size_t at = 0; at == 0 || at < group.size(); at += 65535) {
    const std::size_t n = std::min<std::size_t>(65535, group.size() - at);
    out += static_cast<char>(at + n >= group.size() ? 1 : 0);  // BFINAL, BTYPE 00 (stored)
    out += static_cast<char>(n & 0xff), out += static_cast<char>(n >> 8);
    out += static_cast<char>(~n & 0xff), out += static_cast<char>((~n >> 8) & 0xff);
    out += group.substr(at, n);
  }
  std::string trailer(8, '\0');
  put_i32(trailer, 0, static_cast<std::int32_t>(
                          crc32(0, reinterpret_cast<const Bytef*>(group.data()), static_cast<uInt>(group.size()))));
  put_i32(trailer, 4, static_cast<std::int32_t>(group.size()));
  return out + trailer;
}

/// A definition like OpenClonk's: a group with a mesh, a text file and a nested group.
std::string sample_group() {
  const std::string inner = make_group({{"Graphics.mesh", "inner mesh"}, {"DefCore.txt", "[DefCore]"}});
  return make_group({{"Script.c", "func Initialize() {}"},
                     {"Inner.ocd", inner, true},
                     {"Empty.txt", ""},
                     {"Notes.txt", "last"}});
}

TEST(C4Group, ListsAndReadsAGroupWrittenByTheLayout) {
  const C4Group g = C4Group::parse(sample_group(), "Test.ocd");
  std::vector<std::string> paths;
  for (const auto& e : g.entries()) paths.push_back(e.path + (e.group ? "/" : ""));
  EXPECT_EQ(paths, (std::vector<std::string>{"Script.c", "Inner.ocd/", "Inner.ocd/Graphics.mesh",
                                             "Inner.ocd/DefCore.txt", "Empty.txt", "Notes.txt"}));
  ASSERT_NE(g.find("Inner.ocd/Graphics.mesh"), nullptr);
  EXPECT_EQ(g.read(*g.find("Inner.ocd/Graphics.mesh")), "inner mesh");
  EXPECT_EQ(g.read(*g.find("Script.c")), "func Initialize() {}");
  EXPECT_EQ(g.read(*g.find("Empty.txt")), "");
  EXPECT_EQ(g.read(*g.find("Notes.txt")), "last");
  EXPECT_EQ(g.find("Inner.ocd/Missing"), nullptr);
  // Packed (gzip with OpenClonk's magic) and opened from a file.
  testing::TempDir dir;
  const auto file = dir.write("Test.ocd", pack(sample_group()));
  EXPECT_EQ(openclonk::inflate_c4group(read_binary_file(file), "Test.ocd"), sample_group());
  const C4Group opened = C4Group::open(file);
  EXPECT_EQ(opened.name(), "Test.ocd");
  EXPECT_EQ(opened.entries().size(), 6u);
  EXPECT_EQ(opened.read(*opened.find("Inner.ocd/DefCore.txt")), "[DefCore]");
  // The original gzip magic is accepted too.
  std::string plain_magic = pack(sample_group());
  plain_magic[0] = '\x1f', plain_magic[1] = '\x8b';
  EXPECT_EQ(openclonk::inflate_c4group(plain_magic, "Test.ocd"), sample_group());
}

TEST(C4Group, ReadsTheBundledChippie) {
  const C4Group g = C4Group::open(kChippie);
  EXPECT_EQ(g.entries().size(), 16u);
  const auto* mesh = g.find("Graphics.mesh");
  const auto* skeleton = g.find("Chippie.skeleton");
  const auto* egg = g.find("Egg.ocd");
  ASSERT_TRUE(mesh && skeleton && egg);
  EXPECT_EQ(mesh->size, 42866u);
  EXPECT_EQ(skeleton->size, 9647u);
  EXPECT_TRUE(egg->group);
  EXPECT_EQ(egg->size, 77473u);
  ASSERT_NE(g.find("Egg.ocd/Graphics.mesh"), nullptr);
  EXPECT_EQ(g.find("Egg.ocd/Graphics.mesh")->size, 23078u);
  const ogre::OgreMesh m = ogre::parse_mesh(g.read(*mesh), "Chippie.ocd/Graphics.mesh");
  EXPECT_EQ(m.version, "[MeshSerializer_v1.8]");
  EXPECT_EQ(m.skeleton_link, "Chippie.skeleton");
  const ogre::OgreSkeleton s = ogre::parse_skeleton(g.read(*skeleton), "Chippie.ocd/Chippie.skeleton");
  EXPECT_EQ(s.bones.size(), 14u);
  // A child group's bytes are a group of their own.
  const C4Group child = C4Group::parse(g.read(*egg), "Egg.ocd");
  EXPECT_EQ(child.read(*child.find("Graphics.mesh")), g.read(*g.find("Egg.ocd/Graphics.mesh")));
}

TEST(C4Group, DamagedPackedFilesFailWithTheirName) {
  const std::string packed = read_binary_file(kChippie);
  testing::expect_error<IoError>(
      [&] { openclonk::inflate_c4group("PK\x03\x04 a zip", "Chippie.ocd"); },
      {"Chippie.ocd: not a packed C4Group (magic bytes 50 4B", "expected 1E 8C"});
  testing::expect_error<IoError>([&] { openclonk::inflate_c4group("\x1e", "Chippie.ocd"); },
                                 {"Chippie.ocd", "too short"});
  testing::expect_error<IoError>(
      [&] { openclonk::inflate_c4group(packed.substr(0, packed.size() / 2), "Chippie.ocd"); },
      {"Chippie.ocd: truncated gzip stream after"});
  std::string flipped = packed;
  for (std::size_t i = 5000; i < 5100; ++i) flipped[i] = static_cast<char>(flipped[i] ^ 0x5a);
  testing::expect_error<IoError>([&] { openclonk::inflate_c4group(flipped, "Chippie.ocd"); },
                                 {"Chippie.ocd: corrupt gzip stream"});
  testing::expect_error<IoError>([&] { openclonk::inflate_c4group(packed, "Chippie.ocd", 100000); },
                                 {"Chippie.ocd: decompresses to more than 100000 bytes"});
  testing::TempDir dir;
  testing::expect_error<IoError>([&] { C4Group::open(dir / "Missing.ocd"); },
                                 {"Missing.ocd", "cannot open"});
}

TEST(C4Group, DamagedGroupsFailNamingTheGroupAndEntry) {
  const std::string good = sample_group();
  // Not scrambled, or another format.
  std::string plain = good;
  for (char& c : plain) c = static_cast<char>(c ^ 0xED);
  testing::expect_error<IoError>([&] { C4Group::parse(plain, "Test.ocd"); },
                                 {"Test.ocd: group header (byte offset 0): not a C4Group"});
  testing::expect_error<IoError>([&] { C4Group::parse(good.substr(0, 100), "Test.ocd"); },
                                 {"Test.ocd: group header", "needs 204 bytes"});
  // Cores are read from offset 204 + 316 k; entry 0's name at 204, size at 204 + 268.
  std::string overrun = good;
  put_i32(overrun, 204 + 3 * 316 + 268, 1000);  // Notes.txt
  testing::expect_error<IoError>([&] { C4Group::parse(overrun, "Test.ocd"); },
                                 {"Test.ocd: entry 3 'Notes.txt' (byte offset 1152): overruns the group "
                                  "(offset", "size 1000"});
  std::string negative = good;
  put_i32(negative, 204 + 268, -5);
  testing::expect_error<IoError>([&] { C4Group::parse(negative, "Test.ocd"); },
                                 {"entry 0 'Script.c'", "overruns the group", "size -5"});
  std::string overlap = good;
  put_i32(overlap, 204 + 3 * 316 + 276, 0);  // Notes.txt at Script.c's offset
  testing::expect_error<IoError>([&] { C4Group::parse(overlap, "Test.ocd"); },
                                 {"Test.ocd: entry 3 'Notes.txt'", "overlap those of entry 0"});
  std::string bad_name = good;
  bad_name.replace(204, 8, "../x.txt");
  testing::expect_error<IoError>([&] { C4Group::parse(bad_name, "Test.ocd"); },
                                 {"Test.ocd: entry 0", "'../x.txt' is not a plain file name"});
  std::string long_name = good;
  std::fill(long_name.begin() + 204, long_name.begin() + 204 + 260, 'a');
  testing::expect_error<IoError>([&] { C4Group::parse(long_name, "Test.ocd"); },
                                 {"Test.ocd: entry 0", "name without its terminating NUL"});
  const std::string twice = make_group({{"a.txt", "1"}, {"a.txt", "2"}});
  testing::expect_error<IoError>([&] { C4Group::parse(twice, "Test.ocd"); },
                                 {"Test.ocd: entry 1 'a.txt'", "a second entry of that name"});
  // The entry count must fit the bytes: the header is scrambled, so write it through a group.
  std::string counted = make_group({{"a.txt", "1"}});
  const std::string huge = make_group(std::vector<Item>(1000, Item{"x", ""}));
  counted.replace(0, 204, huge.substr(0, 204));  // a header claiming 1000 entries
  testing::expect_error<IoError>([&] { C4Group::parse(counted, "Test.ocd"); },
                                 {"Test.ocd: group header", "entry count 1000 does not fit"});
  // A damaged child group names its path inside the file.
  const std::string child = make_group({{"Graphics.mesh", "m"}});
  const std::string cut = make_group({{"Inner.ocd", child.substr(0, 150), true}});
  testing::expect_error<IoError>([&] { C4Group::parse(cut, "Test.ocd"); },
                                 {"Test.ocd/Inner.ocd: group header", "needs 204 bytes"});
  std::string child_overrun = child;
  put_i32(child_overrun, 204 + 268, 99);
  testing::expect_error<IoError>(
      [&] { C4Group::parse(make_group({{"Inner.ocd", child_overrun, true}}), "Test.ocd"); },
      {"Test.ocd/Inner.ocd: entry 0 'Graphics.mesh'", "overruns the group"});
}

TEST(C4Group, NestingIsLimited) {
  std::string group = make_group({{"Graphics.mesh", "m"}});
  for (int depth = 0; depth < C4Group::kMaxDepth; ++depth) group = make_group({{"G.ocd", group, true}});
  EXPECT_EQ(C4Group::parse(group, "Deep.ocd").entries().size(), C4Group::kMaxDepth + 1u);
  group = make_group({{"G.ocd", group, true}});
  testing::expect_error<IoError>([&] { C4Group::parse(group, "Deep.ocd"); },
                                 {"Deep.ocd/G.ocd/", "nested more than 16 deep"});
}

TEST(C4Group, CorruptedGroupsNeverCrash) {
  const std::string good = openclonk::inflate_c4group(read_binary_file(kChippie), "Chippie.ocd");
  std::mt19937 rng(11);
  int failed = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::string bytes = good;
    // Damage the header and entry cores (where the structure is).
    for (int k = 0; k < 3; ++k) {
      const std::size_t at = std::uniform_int_distribution<std::size_t>(0, 204 + 9 * 316)(rng);
      bytes[at] = static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
    }
    try {
      const C4Group g = C4Group::parse(bytes, "Chippie.ocd");
      for (const auto& e : g.entries()) EXPECT_EQ(g.read(e).size(), e.size);
    } catch (const IoError& e) {
      ++failed;
      EXPECT_EQ(std::string(e.what()).rfind("Chippie.ocd", 0), 0u) << e.what();
    }
  }
  EXPECT_GT(failed, 0);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::datasets

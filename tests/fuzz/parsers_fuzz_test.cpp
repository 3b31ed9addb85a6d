// Seeded random-mutation fuzzing of the parsers we own (label `long`): RigNet rig text
// (geometry/rig_io.hpp) and our HDF5 dataset reader (data/dataset_file.hpp), with the harness
// of fuzz_harness.hpp (the game-file readers are in readers_fuzz_test.cpp). Every mutated input
// must either parse into something valid or be rejected with skinlab::Error (the clear error
// `skinlab predict` and `skinlab train` report); any other exception, a crash or a hang is a
// failure. Each target runs for a bounded time (SKINLAB_FUZZ_SECONDS, default 60) from a fixed
// seed (SKINLAB_FUZZ_SEED, default 1), and prints how many inputs it tried and how many parsed,
// so a failure can be reproduced with the same seed and count.
//
//   ctest --test-dir build -L long -R Fuzz

#include <H5Cpp.h>
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "framework/data/dataset_file.hpp"
#include "framework/geometry/rig_io.hpp"
#include "tests/data/data_fixtures.hpp"
#include "tests/fuzz/fuzz_harness.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {

namespace fs = std::filesystem;
using fuzz::Tally;
using testing::TempDir;

TEST(Fuzz, RigTextParserRejectsOrAcceptsEveryMutation) {
  TempDir dir;
  std::vector<std::string> seeds;
  for (const char* name : {"box_rig.txt", "cycle_rig.txt", "two_roots_rig.txt",
                           "unknown_joint_rig.txt", "zero_length_rig.txt"}) {
    seeds.push_back(fuzz::read_bytes(fs::path(SKINLAB_SOURCE_DIR) / "tests/data/bad" / name));
  }
  seeds.push_back(fuzz::read_bytes(fs::path(SKINLAB_SOURCE_DIR) / "tests/data/bad/box_rig.txt") +
                  "skin 0 root 1\nskin 1 root 0.5 mid 0.5\nskin 2 mid 1\nskin 3 top 1\n"
                  "skin 4 root 0.25 mid 0.25 top 0.5\nskin 5 top 1\nskin 6 mid 1\nskin 7 root 1\n");
  const Tally t = fuzz::run("rig_text", seeds, fuzz::mutate, [&](const std::string&, const fs::path& file) {
    const geometry::Rig rig = geometry::read_rig(file, 8);
    try {
      rig.skeleton.validate("fuzzed rig");  // what was accepted must be a valid skeleton
    } catch (const Error& e) {
      throw std::logic_error(std::string("accepted an invalid skeleton: ") + e.what());
    }
    for (Eigen::Index v = 0; v < rig.weights.rows(); ++v) {
      const double sum = rig.weights.row(v).sum();
      if (!(std::abs(sum - 1.0) <= 1e-3)) {
        throw std::logic_error("accepted a weight row summing to " + std::to_string(sum));
      }
    }
  });
  EXPECT_GT(t.tried, 100);
  EXPECT_GT(t.rejected, 0);
  EXPECT_EQ(t.failed, 0);
}

/// Byte ranges [offset, offset + size) of the raw storage of every numeric dataset of an HDF5
/// file with contiguous layout (what write_dataset writes with deflate level 0).
std::vector<std::pair<std::size_t, std::size_t>> numeric_storage(const fs::path& file) {
  std::vector<std::pair<std::size_t, std::size_t>> ranges;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  H5Ovisit(
      f, H5_INDEX_NAME, H5_ITER_NATIVE,
      [](hid_t root, const char* name, const H5O_info_t* info, void* out) -> herr_t {
        if (info->type != H5O_TYPE_DATASET) return 0;
        const hid_t d = H5Dopen2(root, name, H5P_DEFAULT);
        const hid_t type = H5Dget_type(d);
        const H5T_class_t cls = H5Tget_class(type);
        const haddr_t offset = H5Dget_offset(d);
        const hsize_t size = H5Dget_storage_size(d);
        if ((cls == H5T_INTEGER || cls == H5T_FLOAT) && offset != HADDR_UNDEF && size > 0) {
          static_cast<std::vector<std::pair<std::size_t, std::size_t>>*>(out)->emplace_back(
              static_cast<std::size_t>(offset), static_cast<std::size_t>(size));
        }
        H5Tclose(type);
        H5Dclose(d);
        return 0;
      },
      &ranges);
  H5Fclose(f);
  return ranges;
}

// Byte mutations of the values of every numeric array (vertices, faces, bones, weights, CSR
// indices, edges, top-K, splits, ...), the part of the file whose meaning only our reader
// checks. HDF5's own structures (superblock, object headers, B-trees, the global heap of the
// strings) are left intact: mutating them exercises libhdf5, not us, and this fuzzer found that
// libhdf5 1.10.8 can loop forever in H5HG_read on a damaged global heap (docs/development.md).
TEST(Fuzz, DatasetReaderRejectsOrAcceptsEveryMutatedValue) {
  TempDir dir;
  data::Dataset dataset;
  dataset.characters.push_back(testing::tiny_character("one"));
  dataset.characters.push_back(testing::tiny_character("two"));
  dataset.splits["random"].train = {0};
  dataset.splits["random"].test = {1};
  data::write_dataset(dir / "seed.h5", dataset, /*deflate_level=*/0);  // contiguous, raw
  const auto ranges = numeric_storage(dir / "seed.h5");
  ASSERT_GT(ranges.size(), 10u);
  const std::vector<std::string> seeds = {fuzz::read_bytes(dir / "seed.h5")};
  auto edit = [&](std::string& s, std::mt19937_64& rng) {
    const auto& [offset, size] = ranges[rng() % ranges.size()];
    const std::size_t at = offset + rng() % size;
    static const unsigned char specials[] = {0x00, 0xff, 0x7f, 0x80, 0x01, 0xfe};
    switch (rng() % 3) {
      case 0: s[at] ^= static_cast<char>(1u << (rng() % 8)); break;
      case 1: s[at] = static_cast<char>(rng() % 256); break;
      default: s[at] = static_cast<char>(specials[rng() % sizeof(specials)]); break;
    }
  };
  const Tally t = fuzz::run("dataset_file", seeds, edit, [&](const std::string&, const fs::path& file) {
    try {
      data::read_dataset(file);
    } catch (const H5::Exception& e) {  // not a std::exception: name it for the finding
      throw std::runtime_error("an H5::Exception escaped from " + e.getFuncName() + ": " +
                               e.getDetailMsg());
    }
  });
  EXPECT_GT(t.tried, 100);
  EXPECT_GT(t.rejected, 0);
  EXPECT_EQ(t.failed, 0);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

// Seeded random-mutation fuzzing of the parsers we own (label `long`): RigNet rig text
// (geometry/rig_io.hpp) and our HDF5 dataset reader (data/dataset_file.hpp). Every mutated
// input must either parse into something valid or be rejected with skinlab::Error (the clear
// error `skinlab predict` and `skinlab train` report); any other exception, a crash or a hang
// is a failure. Each target runs for a bounded time (SKINLAB_FUZZ_SECONDS, default 60) from a
// fixed seed (SKINLAB_FUZZ_SEED, default 1), and prints how many inputs it tried and how many
// parsed, so a failure can be reproduced with the same seed and count.
//
//   ctest --test-dir build -L long -R Fuzz

#include <H5Cpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <stdexcept>
#include <typeinfo>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/core/error.hpp"
#include "framework/data/dataset_file.hpp"
#include "framework/geometry/rig_io.hpp"
#include "tests/data/data_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

double budget_seconds() {
  const char* env = std::getenv("SKINLAB_FUZZ_SECONDS");
  return env != nullptr ? std::atof(env) : 60.0;
}

std::uint64_t seed() {
  const char* env = std::getenv("SKINLAB_FUZZ_SEED");
  return env != nullptr ? std::strtoull(env, nullptr, 10) : 1;
}

/// One random edit of `s`: flip a bit, set a byte, insert or delete a run, duplicate a slice,
/// or splice in a token that parsers tend to mishandle.
void mutate(std::string& s, std::mt19937_64& rng) {
  static const std::vector<std::string> tokens = {
      " ",    "\n",     "\t",  "nan",  "-nan", "inf", "1e400", "-0", "99999999999999999999",
      "-1",   "0x10",   "#",   "root", "hier", "skin", "joints", "\r\n", std::string(1, '\0'),
      "1e-320", "\xff\xfe", "3.4028236e38"};
  auto pick = [&](std::size_t n) { return n == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); };
  switch (pick(6)) {
    case 0:
      if (!s.empty()) s[pick(s.size())] ^= static_cast<char>(1u << pick(8));
      break;
    case 1:
      if (!s.empty()) s[pick(s.size())] = static_cast<char>(pick(256));
      break;
    case 2:
      s.insert(pick(s.size() + 1), tokens[pick(tokens.size())]);
      break;
    case 3:
      if (!s.empty()) {
        const std::size_t at = pick(s.size());
        s.erase(at, 1 + pick(std::min<std::size_t>(16, s.size() - at)));
      }
      break;
    case 4:
      if (!s.empty()) {
        const std::size_t at = pick(s.size());
        const std::string slice = s.substr(at, 1 + pick(64));
        s.insert(pick(s.size() + 1), slice);
      }
      break;
    default:
      if (s.size() > 1) s.resize(pick(s.size()));  // truncation
      break;
  }
}

struct Tally {
  long tried = 0, parsed = 0, rejected = 0;
};

/// Mutates `seeds` (1–4 edits of `edit` each) until the time budget is spent, calls `parse` on
/// each mutant written to `file`; `parse` returns normally for a valid input and throws for a
/// bad one.
template <class Edit, class Parse>
Tally fuzz(const std::vector<std::string>& seeds, const fs::path& file, Edit edit, Parse parse) {
  std::mt19937_64 rng(seed());
  Tally t;
  const auto end = std::chrono::steady_clock::now() +
                   std::chrono::duration<double>(budget_seconds());
  while (std::chrono::steady_clock::now() < end) {
    std::string input = seeds[t.tried % seeds.size()];
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) edit(input, rng);
    write_file_atomic(file, input);
    ++t.tried;
    try {
      parse();
      ++t.parsed;
    } catch (const Error&) {
      ++t.rejected;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "input " << t.tried << " (seed " << seed() << ") threw "
                    << typeid(e).name() << " instead of skinlab::Error: " << e.what();
      write_file_atomic(file.string() + ".failure", input);
      return t;
    } catch (const H5::Exception& e) {
      ADD_FAILURE() << "input " << t.tried << " (seed " << seed() << ") let an H5::Exception "
                    << "escape from " << e.getFuncName() << ": " << e.getDetailMsg();
      write_file_atomic(file.string() + ".failure", input);
      return t;
    } catch (...) {
      ADD_FAILURE() << "input " << t.tried << " (seed " << seed() << ") threw a non-std exception";
      write_file_atomic(file.string() + ".failure", input);
      return t;
    }
  }
  return t;
}

TEST(Fuzz, RigTextParserRejectsOrAcceptsEveryMutation) {
  TempDir dir;
  std::vector<std::string> seeds;
  for (const char* name : {"box_rig.txt", "cycle_rig.txt", "two_roots_rig.txt",
                           "unknown_joint_rig.txt", "zero_length_rig.txt"}) {
    seeds.push_back(read_file(fs::path(SKINLAB_SOURCE_DIR) / "tests/data/bad" / name));
  }
  seeds.push_back(read_file(fs::path(SKINLAB_SOURCE_DIR) / "tests/data/bad/box_rig.txt") +
                  "skin 0 root 1\nskin 1 root 0.5 mid 0.5\nskin 2 mid 1\nskin 3 top 1\n"
                  "skin 4 root 0.25 mid 0.25 top 0.5\nskin 5 top 1\nskin 6 mid 1\nskin 7 root 1\n");
  const fs::path file = dir / "rig.txt";
  const Tally t = fuzz(seeds, file, mutate, [&] {
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
  std::cout << "rig text: " << t.tried << " inputs, " << t.parsed << " parsed, " << t.rejected
            << " rejected\n";
  EXPECT_GT(t.tried, 100);
  EXPECT_GT(t.rejected, 0);
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
  const std::vector<std::string> seeds = {read_file(dir / "seed.h5")};
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
  const fs::path file = dir / "fuzzed.h5";
  const Tally t = fuzz(seeds, file, edit, [&] { data::read_dataset(file); });
  std::cout << "dataset file: " << t.tried << " inputs, " << t.parsed << " parsed, " << t.rejected
            << " rejected\n";
  EXPECT_GT(t.tried, 100);
  EXPECT_GT(t.rejected, 0);
}

}  // namespace
}  // namespace skinlab

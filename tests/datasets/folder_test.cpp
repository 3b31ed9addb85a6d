// The `folder` builder's selection and naming options (include, exclude, skeleton, prefix), its
// resolution of a `repository` source under SKINLAB_DATA_DIR with the errors a user meets
// before fetching, and the renormalisation of weights, on OBJ + rig text files the tests write.

#include "datasets/folder/folder.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>

#include "framework/core/registry.hpp"
#include "tests/test_util.hpp"

namespace skinlab::datasets {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::TempDir;

const std::string kCommit = "0123456789abcdef0123456789abcdef01234567";

/// A tetrahedron bound to two joints; `weight_sum` scales the weights of vertex 0.
void write_character(const TempDir& dir, const std::string& stem, double weight_sum = 1.0) {
  dir.write(stem + ".obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  dir.write(stem + "_rig.txt",
            "joints root 0 0 0\njoints tip 0 1 0\nroot root\nhier root tip\n"
            "skin 0 root " + std::to_string(0.5 * weight_sum) + " tip " +
                std::to_string(0.5 * weight_sum) +
                "\nskin 1 root 1\nskin 2 tip 1\nskin 3 root 0.25 tip 0.75\n");
}

std::shared_ptr<DatasetBuilder> folder(const std::string& yaml) {
  return dataset_registry().create(config::Config::parse("type: folder\n" + yaml).root());
}

Folder::Options options(const std::string& yaml) {
  return Folder::Options::from(config::Config::parse("type: folder\n" + yaml).root());
}

/// Sets or unsets an environment variable for the lifetime of the object.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::optional<std::string>& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) {
      ::setenv(name, value->c_str(), 1);
    } else {
      ::unsetenv(name);
    }
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(Folder, GlobsMatchAsDocumented) {
  EXPECT_TRUE(glob_match("*.glb", "a.glb"));
  EXPECT_FALSE(glob_match("*.glb", "pack/a.glb")) << "'*' does not cross '/'";
  EXPECT_TRUE(glob_match("**/*.glb", "a.glb")) << "'**/' matches no directory too";
  EXPECT_TRUE(glob_match("**/*.glb", "pack/sub/a.glb"));
  EXPECT_TRUE(glob_match("pack/**", "pack/sub/a.glb"));
  EXPECT_FALSE(glob_match("pack/**", "other/a.glb"));
  EXPECT_TRUE(glob_match("pack_?/a.glb", "pack_1/a.glb"));
  EXPECT_FALSE(glob_match("pack_?/a.glb", "pack_12/a.glb"));
  EXPECT_TRUE(glob_match("fish/Fish3.glb", "fish/Fish3.glb"));
  EXPECT_FALSE(glob_match("fish/Fish3.glb", "fish/Fish3.glb.import"));
  EXPECT_TRUE(glob_match("*_rig*", "a_rig.txt"));
}

TEST(Folder, TodaysOptionsBehaveAsBefore) {
  TempDir dir;
  write_character(dir, "top");
  write_character(dir, "pack/inner");
  dir.write("notes.txt", "not a character");
  std::vector<Excluded> excluded;
  const auto flat = folder("path: " + dir.path().string())->read(excluded);
  ASSERT_EQ(flat.size(), 1u);
  EXPECT_EQ(flat[0].character.name, "top");
  EXPECT_EQ(flat[0].skeleton, "top") << "family: the file stem";
  EXPECT_EQ(flat[0].source, "folder");
  EXPECT_EQ(flat[0].path, "top.obj");
  EXPECT_TRUE(excluded.empty());

  const auto deep = folder("path: " + dir.path().string() + "\nrecursive: true\nskeleton: fam")
                        ->read(excluded);
  ASSERT_EQ(deep.size(), 2u);
  EXPECT_EQ(deep[0].character.name, "pack.inner");
  EXPECT_EQ(deep[0].skeleton, "fam");
  EXPECT_EQ(deep[1].character.name, "top");
}

TEST(Folder, IncludeExcludeDirectoryFamilyAndPrefix) {
  TempDir dir;
  write_character(dir, "pack_a/one");
  write_character(dir, "pack_a/chest");
  write_character(dir, "pack_b/two");
  write_character(dir, "pack_b/deep/three");
  write_character(dir, "top");
  const auto builder = folder("path: " + dir.path().string() +
                              "\ninclude: ['pack_*/*.obj', 'pack_b/deep/three.obj']"
                              "\nexclude: {pack_a/chest.obj: 'a rigged prop, not a character'}"
                              "\nskeleton: directory\nprefix: t.");
  std::vector<Excluded> excluded;
  const auto read = builder->read(excluded);
  ASSERT_EQ(read.size(), 3u);
  EXPECT_EQ(read[0].character.name, "t.pack_a.one");
  EXPECT_EQ(read[0].skeleton, "pack_a");
  EXPECT_EQ(read[1].character.name, "t.pack_b.deep.three");
  EXPECT_EQ(read[1].skeleton, "deep");
  EXPECT_EQ(read[2].character.name, "t.pack_b.two");
  EXPECT_EQ(read[2].skeleton, "pack_b");
  ASSERT_EQ(excluded.size(), 1u) << "top.obj is not included, so neither read nor excluded";
  EXPECT_EQ(excluded[0].source, "folder");
  EXPECT_EQ(excluded[0].path, "pack_a/chest.obj");
  EXPECT_EQ(excluded[0].reason, "a rigged prop, not a character");
}

TEST(Folder, PatternsThatMatchNothingAreErrors) {
  TempDir dir;
  write_character(dir, "pack/one");
  std::vector<Excluded> excluded;
  testing::expect_error<ConfigError>(
      [&] {
        folder("path: " + dir.path().string() + "\nrecursive: true\nexclude: {pack/on.obj: typo}")
            ->read(excluded);
      },
      {"exclude pattern 'pack/on.obj'", "matches no character file", dir.path().string()});
  testing::expect_error<ConfigError>(
      [&] { folder("path: " + dir.path().string() + "\ninclude: ['*.glb']")->read(excluded); },
      {"include pattern '*.glb'", "matches no character file"});
  testing::expect_error<ConfigError>(
      [&] { options("path: x\nexclude: [a.obj]"); }, {"exclude", "expected a map"});
  testing::expect_error<ConfigError>(
      [&] { options("path: x\nexclude: {a.obj: ''}"); }, {"reason must not be empty"});
}

TEST(Folder, FilesWithoutWeightsOrRigAreReported) {
  TempDir dir;
  write_character(dir, "good");
  dir.write("lonely.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  dir.write("bare.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  dir.write("bare_rig.txt", "joints root 0 0 0\njoints tip 0 1 0\nroot root\nhier root tip\n");
  std::vector<Excluded> excluded;
  const auto read = folder("path: " + dir.path().string())->read(excluded);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].character.name, "bare");
  EXPECT_FALSE(read[0].character.has_weights()) << "dropped by cleaning as 'no skin weights'";
  ASSERT_EQ(excluded.size(), 1u);
  EXPECT_EQ(excluded[0].path, "lonely.obj");
  EXPECT_NE(excluded[0].reason.find("without its RigNet rig file lonely_rig.txt"),
            std::string::npos)
      << excluded[0].reason;
}

TEST(Folder, WeightsThatDoNotSumToOneAreRenormalised) {
  TempDir dir;
  write_character(dir, "half", 0.5);
  std::vector<Excluded> excluded;
  const auto read = folder("path: " + dir.path().string())->read(excluded);
  ASSERT_EQ(read.size(), 1u) << (excluded.empty() ? "" : excluded[0].reason);
  const auto& W = read[0].character.weights;
  for (Eigen::Index v = 0; v < W.rows(); ++v) EXPECT_NEAR(W.row(v).sum(), 1.0, 1e-12);
  EXPECT_NEAR(W.coeff(0, 0), 0.5, 1e-12);
  EXPECT_NEAR(W.coeff(3, 1), 0.75, 1e-12);
}

TEST(Folder, RepositoryResolvesUnderTheDataFolder) {
  TempDir data;
  write_character(data, "owner/name/models/pack/one");
  ScopedEnv env("SKINLAB_DATA_DIR", data.path().string());
  const std::string yaml = "repository: owner/name\ncommit: " + kCommit +
                           "\npath: models\nrecursive: true\nskeleton: directory";
  const Folder builder(options(yaml));
  EXPECT_EQ(builder.root(), data.path() / "owner/name/models");
  std::vector<Excluded> excluded;
  const auto read = builder.read(excluded);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].character.name, "pack.one");
  EXPECT_EQ(read[0].source, "owner/name") << "the card lists the repository as the source";
  EXPECT_EQ(read[0].path, "pack/one.obj");
  EXPECT_EQ(read[0].skeleton, "pack");

  // Without path: the repository's root.
  EXPECT_EQ(Folder(options("repository: owner/name\ncommit: " + kCommit)).root(),
            data.path() / "owner/name");

  // A checkout at another commit is refused; at the commit (as fetch_data leaves it) accepted.
  data.write("owner/name/.git/HEAD", std::string(40, 'f') + "\n");
  testing::expect_error<IoError>([&] { builder.root(); },
                                 {"checked out at " + std::string(40, 'f'), kCommit,
                                  "scripts/fetch_data"});
  data.write("owner/name/.git/HEAD", kCommit + "\n");
  EXPECT_EQ(builder.read(excluded).size(), 1u);
}

TEST(Folder, RepositoryErrorsTellHowToFetch) {
  TempDir data;
  const std::string yaml = "repository: owner/name\ncommit: " + kCommit;
  {
    ScopedEnv env("SKINLAB_DATA_DIR", std::nullopt);
    std::vector<Excluded> excluded;
    testing::expect_error<IoError>([&] { folder(yaml)->read(excluded); },
                                   {"SKINLAB_DATA_DIR", "is not set", "owner/name", kCommit,
                                    "scripts/fetch_data"});
  }
  ScopedEnv env("SKINLAB_DATA_DIR", data.path().string());
  std::vector<Excluded> excluded;
  testing::expect_error<IoError>(
      [&] { folder(yaml)->read(excluded); },
      {"repository owner/name", "expected " + (data.path() / "owner/name").string(),
       "SKINLAB_DATA_DIR=" + data.path().string(), "scripts/fetch_data"});
}

TEST(Folder, RepositoryOptionsAreChecked) {
  testing::expect_error<ConfigError>([] { options("repository: owner/name"); },
                                     {"commit", "is required with 'repository'"});
  testing::expect_error<ConfigError>([] { options("repository: owner/name\ncommit: abc123"); },
                                     {"commit", "40 lowercase hex digits", "abc123"});
  testing::expect_error<ConfigError>([] { options("path: x\ncommit: " + kCommit); },
                                     {"commit", "only meaningful with 'repository"});
  testing::expect_error<ConfigError>([] { options("repository: owner\ncommit: " + kCommit); },
                                     {"repository", "owner/name"});
  testing::expect_error<ConfigError>(
      [] { options("repository: owner/name\ncommit: " + kCommit + "\npath: /abs"); },
      {"path", "inside the repository"});
  testing::expect_error<ConfigError>(
      [] { options("repository: owner/name\ncommit: " + kCommit + "\npath: ../other"); },
      {"path", "inside the repository"});
  testing::expect_error<ConfigError>([] { options("licence: CC0-1.0"); }, {"path"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::datasets

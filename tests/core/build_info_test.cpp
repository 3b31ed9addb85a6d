// The build-time record of the source tree's git state (cmake/build_info.cmake) and how env.json
// carries it.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <regex>
#include <string>

#include "framework/core/atomic_file.hpp"
#include "framework/core/environment.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

namespace fs = std::filesystem;
using testing::TempDir;

int sh(const std::string& command) { return std::system(("(" + command + ") > /dev/null 2>&1").c_str()); }

/// Runs the build's script on `tree`, writing `out`.
void record(const fs::path& tree, const fs::path& out) {
  ASSERT_EQ(sh("cmake -DSOURCE_DIR='" + tree.string() + "' -DOUTPUT='" + out.string() + "' -P '" +
               SKINLAB_SOURCE_DIR "/cmake/build_info.cmake'"),
            0);
}

TEST(BuildInfo, RecordsCommitModifiedFilesAndDiffHash) {
  ASSERT_EQ(sh("command -v git && command -v cmake"), 0) << "needs git and cmake on PATH";
  TempDir dir;
  const fs::path tree = dir / "tree", out = dir / "build_info.cpp";
  fs::create_directories(tree);
  const std::string git = "git -C '" + tree.string() + "' -c user.name=t -c user.email=t@t ";
  write_file_atomic(tree / "a.txt", "one\n");
  write_file_atomic(tree / "b c.txt", "two\n");
  ASSERT_EQ(sh(git + "init -q && " + git + "add -A && " + git + "commit -qm x"), 0);

  record(tree, out);
  const std::string clean = read_file(out);
  EXPECT_TRUE(std::regex_search(clean, std::regex("\\{\"[0-9a-f]{40}\", false, \\{\\}, \"\"\\}")))
      << clean;
  const auto stamp = fs::last_write_time(out);

  // unchanged tree: the file is not rewritten (nothing recompiles)
  record(tree, out);
  EXPECT_EQ(fs::last_write_time(out), stamp);

  // a modified tracked file: dirty, listed, and a SHA-256 of the diff
  write_file_atomic(tree / "b c.txt", "changed\n");
  record(tree, out);
  const std::string dirty = read_file(out);
  EXPECT_NE(dirty.find("true, {\"b c.txt\", }"), std::string::npos) << dirty;
  std::smatch hash;
  ASSERT_TRUE(std::regex_search(dirty, hash, std::regex("\"([0-9a-f]{64})\"\\}"))) << dirty;
  // another change of the same file: another hash
  write_file_atomic(tree / "b c.txt", "changed again\n");
  record(tree, out);
  EXPECT_EQ(read_file(out).find(hash[1].str()), std::string::npos);

  // not a work tree: commit unknown, and still a valid record
  const fs::path plain = dir / "plain";
  fs::create_directories(plain);
  record(plain, out);
  EXPECT_NE(read_file(out).find("{\"unknown\", false, {}, \"\"}"), std::string::npos);
}

TEST(BuildInfo, EnvJsonListsModifiedFilesOnlyWhenDirty) {
  const nlohmann::json clean = git_json(GitState{"abc", false, {}, ""});
  EXPECT_EQ(clean, (nlohmann::json{{"git_commit", "abc"}, {"git_dirty", false}}));
  const nlohmann::json dirty = git_json(GitState{"abc", true, {"x.cpp", "y.hpp"}, "f00d"});
  EXPECT_EQ(dirty["git_modified"], nlohmann::json::array({"x.cpp", "y.hpp"}));
  EXPECT_EQ(dirty["git_diff_sha256"], "f00d");
  // env.json carries the build's record
  const nlohmann::json env = collect_environment(1, {});
  EXPECT_EQ(env["git_commit"], build_git_state().commit);
  EXPECT_EQ(env["git_dirty"], build_git_state().dirty);
  EXPECT_EQ(env.contains("git_diff_sha256"), build_git_state().dirty);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

// joined_keys and joined (framework/core/text.hpp): the lists of what exists in error messages.
#include "framework/core/text.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>
#include <vector>

namespace skinlab {
namespace {

TEST(JoinedKeys, KeysInTheMapsOrderOrTheWordForNone) {
  const std::map<std::string, int> priors{{"geo_voxel", 2}, {"bone_heat", 1}};
  EXPECT_EQ(joined_keys(priors), "bone_heat, geo_voxel");
  EXPECT_EQ(joined_keys(std::map<std::string, int>{{"random", 0}}), "random");
  EXPECT_EQ(joined_keys(std::map<std::string, double>{}), "none");
  EXPECT_EQ(joined_keys(std::map<std::string, double>{}, "(none)"), "(none)");
}

TEST(Joined, ValuesInTheContainersOrderOrTheWordForNone) {
  EXPECT_EQ(joined(std::set<std::string>{"zeroad", "cube2"}), "cube2, zeroad");
  EXPECT_EQ(joined(std::vector<std::string>{"zeroad", "cube2"}), "zeroad, cube2");
  EXPECT_EQ(joined(std::vector<std::string>{}), "none");
  EXPECT_EQ(joined(std::vector<std::string>{}, "(none)"), "(none)");
}

}  // namespace
}  // namespace skinlab

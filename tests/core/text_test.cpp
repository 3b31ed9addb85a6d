// joined_keys (framework/core/text.hpp): the lists of what exists in error messages.
#include "framework/core/text.hpp"

#include <gtest/gtest.h>

#include <map>
#include <string>

namespace skinlab {
namespace {

TEST(JoinedKeys, KeysInTheMapsOrderOrTheWordForNone) {
  const std::map<std::string, int> priors{{"geo_voxel", 2}, {"bone_heat", 1}};
  EXPECT_EQ(joined_keys(priors), "bone_heat, geo_voxel");
  EXPECT_EQ(joined_keys(std::map<std::string, int>{{"random", 0}}), "random");
  EXPECT_EQ(joined_keys(std::map<std::string, double>{}), "none");
  EXPECT_EQ(joined_keys(std::map<std::string, double>{}, "(none)"), "(none)");
}

}  // namespace
}  // namespace skinlab

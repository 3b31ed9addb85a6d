// Every plug-in of the program, as the program links them (framework/CMakeLists.txt,
// skinlab_all): the exact keys of every registry.

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "framework/core/registry.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

// The exact keys of every category. Grows as plug-ins land; a missing key here means a
// registrar was dropped by the linker or a plug-in was renamed.
TEST(Registry, ExactKeysOfEveryCategory) {
  EXPECT_NO_THROW(verify_registries());
  std::map<std::string, std::vector<std::string>> actual;
  for (const auto* registry : all_registries()) actual[registry->name()] = registry->keys();
  const std::map<std::string, std::vector<std::string>> expected = {
      {"distance", {"euclidean", "hollow_dist", "volumetric_geodesic"}},
      {"graph_op",
       {"b2v", "edge_conv", "gat_block", "gconv_pool", "global_pool", "mean_conv", "mesh_conv",
        "v2b"}},
      {"model", {"heterskinnet", "neuroskinning", "rignet_skin"}},
      {"corrective_model", {"densegats", "neuroskinning"}},
      {"loss", {"kl", "laplacian_smoothing", "mse", "prior_kl", "soft_cross_entropy"}},
      {"metric", {"avg_l1", "deformation_error", "dominant_joint", "precision_recall"}},
      {"dataset", {"cube2", "folder", "nexuiz", "ogre", "openclonk", "zeroad"}},
      {"binder", {"bone_heat", "geo_voxel"}},
      {"task", {"corrective", "sequence", "skinning"}},
  };
  EXPECT_EQ(actual, expected);
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab

#include "datasets/zeroad/read_actor.hpp"

#include <functional>

#include "datasets/zeroad/parse_xml.hpp"
#include "framework/core/error.hpp"

namespace skinlab::datasets::zeroad {

ActorRefs read_actor(const std::string& xml, const std::string& source) {
  const auto root = parse_xml(xml, source);
  ActorRefs refs;
  std::function<void(const XmlElement&)> walk = [&](const XmlElement& e) {
    if (e.name == "mesh" && !e.text.empty()) refs.meshes.push_back(e.text);
    if (e.name == "animation") {
      // An animation without file is a role the engine plays as "no motion" (e.g. a building's
      // idle); it names no clip.
      const std::string file = e.attribute("file");
      if (!file.empty()) refs.animations.push_back({e.attribute("name"), file});
    }
    if (e.name == "variant" && !e.attribute("file").empty()) {
      refs.variant_files.push_back(e.attribute("file"));
    }
    for (const auto& c : e.children) walk(*c);
  };
  walk(*root);
  return refs;
}

}  // namespace skinlab::datasets::zeroad

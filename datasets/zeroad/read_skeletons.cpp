#include "datasets/zeroad/read_skeletons.hpp"

#include <algorithm>
#include <functional>
#include <set>

#include "datasets/zeroad/parse_xml.hpp"
#include "framework/core/error.hpp"

namespace skinlab::datasets::zeroad {

namespace {

[[noreturn]] void fail(const std::string& source, const XmlElement& e, const std::string& msg) {
  throw Error(source + ":" + std::to_string(e.line) + ": <" + e.name + ">: " + msg);
}

}  // namespace

SkeletonFile read_skeletons(const std::string& xml, const std::string& source) {
  const auto root = parse_xml(xml, source);
  if (root->name != "skeletons") fail(source, *root, "expected <skeletons> as the root element");
  SkeletonFile out;
  for (const auto& node : root->children) {
    if (node->name == "standard_skeleton") {
      StandardSkeleton s;
      s.id = node->attribute("id");
      s.title = node->attribute("title");
      s.file = source;
      if (s.id.empty()) fail(source, *node, "standard skeleton without id");
      std::set<std::string> seen;
      std::function<void(const XmlElement&, int)> walk = [&](const XmlElement& e, int parent) {
        for (const auto& c : e.children) {
          if (c->name != "bone") continue;
          const std::string name = c->attribute("name");
          if (name.empty())
            fail(source, *c, "bone without name in standard skeleton '" + s.id + "'");
          if (!seen.insert(name).second) {
            fail(source, *c, "duplicate bone '" + name + "' in standard skeleton '" + s.id + "'");
          }
          s.names.push_back(name);
          s.parents.push_back(parent);
          walk(*c, static_cast<int>(s.names.size()) - 1);
        }
      };
      walk(*node, -1);
      if (s.names.empty()) fail(source, *node, "standard skeleton '" + s.id + "' has no bones");
      out.standard.push_back(std::move(s));
    } else if (node->name == "skeleton") {
      TargetSkeleton t;
      t.title = node->attribute("title");
      t.target = node->attribute("target");
      t.file = source;
      if (t.target.empty()) fail(source, *node, "skeleton without target");
      const XmlElement* id = node->child("identifier");
      const XmlElement* id_root = id ? id->child("root") : nullptr;
      if (!id_root || id_root->text.empty())
        fail(source, *node, "skeleton without <identifier><root>");
      t.root = id_root->text;
      std::function<void(const XmlElement&, const std::string&)> walk =
          [&](const XmlElement& e, const std::string& inherited) {
            for (const auto& c : e.children) {
              if (c->name != "bone") continue;
              const std::string name = c->attribute("name");
              if (name.empty()) fail(source, *c, "bone without name in skeleton '" + t.title + "'");
              const XmlElement* target = c->child("target");
              const std::string mapped = target ? target->text : inherited;
              t.names.push_back(name);
              t.targets.push_back(mapped);
              walk(*c, mapped);
            }
          };
      walk(*node, "");
      // Check targets against a standard skeleton of that id in this file, when there is one.
      for (const auto& s : out.standard) {
        if (s.id != t.target) continue;
        for (std::size_t i = 0; i < t.names.size(); ++i) {
          if (!t.targets[i].empty() &&
              std::find(s.names.begin(), s.names.end(), t.targets[i]) == s.names.end()) {
            fail(source, *node,
                 "bone '" + t.names[i] + "' targets '" + t.targets[i] +
                     "', which is not a bone of standard skeleton '" + s.id + "'");
          }
        }
      }
      out.mapped.push_back(std::move(t));
    }
  }
  return out;
}

}  // namespace skinlab::datasets::zeroad

#pragma once
/// \file
/// A minimal element tree for 0 A.D.'s small XML files (skeletons, actors, variants), parsed with
/// expat. Only elements, attributes, character data and line numbers are kept: that is all the
/// skeleton and actor readers need, and the line lets every error name its element.

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace skinlab::datasets::zeroad {

struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::string text;  ///< concatenated character data directly inside, trimmed
  int line = 0;      ///< 1-based line of the start tag
  std::vector<std::unique_ptr<XmlElement>> children;

  /// Attribute value, or "" when absent.
  std::string attribute(const std::string& key) const;
  /// First child element named `child`, or null.
  const XmlElement* child(const std::string& child) const;
};

/// Parses `xml` into its root element. Throws Error "source:line: XML error: ..." on malformed
/// input (expat's message and line).
std::unique_ptr<XmlElement> parse_xml(const std::string& xml, const std::string& source);

}  // namespace skinlab::datasets::zeroad

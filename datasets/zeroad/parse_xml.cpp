#include "datasets/zeroad/parse_xml.hpp"

#include <expat.h>

#include "framework/core/error.hpp"

namespace skinlab::datasets::zeroad {

std::string XmlElement::attribute(const std::string& key) const {
  auto it = attributes.find(key);
  return it == attributes.end() ? std::string() : it->second;
}

const XmlElement* XmlElement::child(const std::string& name_) const {
  for (const auto& c : children)
    if (c->name == name_) return c.get();
  return nullptr;
}

namespace {

/// Deeper nesting is rejected: the tree is built, walked and destroyed recursively, so a file
/// of a million nested elements (7 MB) overflowed the stack; the deepest of 0ad-data 0.0.26's
/// art/ XML files (skeletons/elephantidae_asian.xml) nests 18 deep.
constexpr std::size_t kMaxDepth = 256;

struct State {
  XML_Parser parser;
  std::unique_ptr<XmlElement> root;
  std::vector<XmlElement*> stack;
  std::string error;  ///< why parsing was stopped (no exception crosses expat's C frames)
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

void on_start(void* data, const XML_Char* name, const XML_Char** attrs) {
  auto* st = static_cast<State*>(data);
  if (st->stack.size() >= kMaxDepth) {
    st->error = ": <" + std::string(name) + ">: elements nested more than " +
                std::to_string(kMaxDepth) + " deep";
    XML_StopParser(st->parser, XML_FALSE);
    return;
  }
  auto e = std::make_unique<XmlElement>();
  e->name = name;
  e->line = static_cast<int>(XML_GetCurrentLineNumber(st->parser));
  for (int i = 0; attrs[i]; i += 2) e->attributes[attrs[i]] = attrs[i + 1];
  XmlElement* raw = e.get();
  if (st->stack.empty()) {
    st->root = std::move(e);
  } else {
    st->stack.back()->children.push_back(std::move(e));
  }
  st->stack.push_back(raw);
}

void on_end(void* data, const XML_Char*) {
  auto* st = static_cast<State*>(data);
  if (!st->error.empty()) return;  // stopped inside a start tag that was not kept
  st->stack.back()->text = trim(st->stack.back()->text);
  st->stack.pop_back();
}

void on_text(void* data, const XML_Char* s, int len) {
  auto* st = static_cast<State*>(data);
  if (!st->stack.empty()) st->stack.back()->text.append(s, static_cast<std::size_t>(len));
}

}  // namespace

std::unique_ptr<XmlElement> parse_xml(const std::string& xml, const std::string& source) {
  State st;
  st.parser = XML_ParserCreate(nullptr);
  if (!st.parser) throw Error(source + ": cannot create an XML parser");
  XML_SetUserData(st.parser, &st);
  XML_SetElementHandler(st.parser, on_start, on_end);
  XML_SetCharacterDataHandler(st.parser, on_text);
  const bool ok =
      XML_Parse(st.parser, xml.data(), static_cast<int>(xml.size()), 1) == XML_STATUS_OK;
  std::string message;
  if (!ok) {
    message = source + ":" + std::to_string(XML_GetCurrentLineNumber(st.parser)) +
              (st.error.empty() ? ": XML error: " + std::string(XML_ErrorString(XML_GetErrorCode(st.parser)))
                                : st.error);
  }
  XML_ParserFree(st.parser);
  if (!ok) throw Error(message);
  if (!st.root) throw Error(source + ": XML error: no root element");
  return std::move(st.root);
}

}  // namespace skinlab::datasets::zeroad

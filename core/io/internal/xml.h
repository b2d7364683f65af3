// A small XML reader for the formats that describe their data in XML (E57): elements,
// attributes and text, with comments, processing instructions and CDATA sections understood and
// the five named entities and numeric character references decoded. No DTDs, no namespaces
// resolved (a prefixed name is kept as it is written: "nor:normalX").
#ifndef NEURALMESH_CORE_IO_INTERNAL_XML_H_
#define NEURALMESH_CORE_IO_INTERNAL_XML_H_

#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh::io_internal {

struct XmlElement {
  std::string name;
  std::vector<std::pair<std::string, std::string>> attributes;  // In the order written.
  std::string text;  // The element's own character data, concatenated (children's excluded).
  std::vector<XmlElement> children;

  // The first child named `child_name`, or null.
  const XmlElement* Child(absl::string_view child_name) const;
  // The value of attribute `attribute_name`, or null.
  const std::string* Attribute(absl::string_view attribute_name) const;
};

// The most deeply nested elements ParseXml takes (E57 files nest about eight deep).
inline constexpr int kMaxXmlDepth = 64;

// Parses a document with one root element. Returns INVALID_ARGUMENT saying what is wrong and on
// which line for malformed markup, mismatched or unclosed tags, an undefined entity, a
// document type declaration, or elements nested deeper than kMaxXmlDepth.
absl::StatusOr<XmlElement> ParseXml(absl::string_view document);

// `text` with &, <, > and " written as entities, for attribute values and text.
std::string EscapeXml(absl::string_view text);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_XML_H_

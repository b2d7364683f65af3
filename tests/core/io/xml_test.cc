// The XML reader of the E57 format (core/io/internal/xml.h): elements, attributes and text with
// comments, processing instructions, CDATA and references understood; malformed documents
// refused with the line and what is wrong.
#include "core/io/internal/xml.h"

#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace neuralmesh::io_internal {
namespace {

using ::testing::HasSubstr;

TEST(XmlTest, ElementsAttributesAndTextAreRead) {
  const absl::StatusOr<XmlElement> root = ParseXml(
      "\xEF\xBB\xBF<?xml version=\"1.0\"?>\n<!-- a comment -->\n"
      "<root type='Structure' xmlns:nor=\"http://example\">\n"
      "  <a type=\"Float\">1.5</a>\n"
      "  <nor:b x=\"&lt;&amp;&quot;&#65;&#x42;\"/>\n"
      "  <c><![CDATA[<not markup> & more]]> and &gt; text</c>\n"
      "</root>\n");
  ASSERT_TRUE(root.ok()) << root.status();
  EXPECT_EQ(root->name, "root");
  EXPECT_EQ(*root->Attribute("type"), "Structure");
  EXPECT_EQ(root->Attribute("missing"), nullptr);
  ASSERT_EQ(root->children.size(), 3u);
  EXPECT_EQ(root->Child("a")->text, "1.5");
  EXPECT_EQ(*root->Child("nor:b")->Attribute("x"), "<&\"AB");
  EXPECT_EQ(root->Child("c")->text, "<not markup> & more and > text");
  EXPECT_EQ(root->Child("d"), nullptr);
}

TEST(XmlTest, MalformedDocumentsAreRefusedWithTheLine) {
  const std::pair<const char*, const char*> cases[] = {
      {"<a>\n<b>\n</a>", "line 3: end tag </a> where <b> ends"},
      {"<a>\n<b/>", "the document ends inside <a>"},
      {"<a/><b/>", "a second root element"},
      {"text<a/>", "text before the root element"},
      {"<a x=1/>", "attribute x of <a> has no quoted value"},
      {"<a x='1' x='2'/>", "attribute x twice in <a>"},
      {"<a>&nbsp;</a>", "undefined entity &'nbsp';"},
      {"<a>&#0;</a>", "character reference &#0; is not a character"},
      {"<!DOCTYPE a><a/>", "document type declarations are not supported"},
      {"<a><!-- open", "a comment without its '-->'"},
      {"", "no root element"},
  };
  for (const auto& [document, message] : cases) {
    const absl::StatusOr<XmlElement> root = ParseXml(document);
    ASSERT_FALSE(root.ok()) << document;
    EXPECT_EQ(root.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(root.status().message()), HasSubstr(message)) << document;
  }
  std::string deep;
  for (int i = 0; i <= kMaxXmlDepth; ++i) deep += "<a>";
  EXPECT_THAT(std::string(ParseXml(deep).status().message()),
              HasSubstr("elements nested more than 64 deep"));
}

TEST(XmlTest, EscapedTextReadsBackAsWritten) {
  const std::string text = "a < b & \"c\" > d";
  const absl::StatusOr<XmlElement> root =
      ParseXml("<r v=\"" + EscapeXml(text) + "\">" + EscapeXml(text) + "</r>");
  ASSERT_TRUE(root.ok()) << root.status();
  EXPECT_EQ(*root->Attribute("v"), text);
  EXPECT_EQ(root->text, text);
}

}  // namespace
}  // namespace neuralmesh::io_internal

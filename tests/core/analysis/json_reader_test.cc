#include "core/analysis/json_reader.h"

#include <string>

#include "absl/strings/str_cat.h"
#include "core/analysis/json_writer.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

using ::testing::HasSubstr;

TEST(JsonReaderTest, ReadsEveryKindOfValue) {
  const absl::StatusOr<JsonValue> doc = ParseJson(
      " {\"a\": [1, -2.5e3, 0.125], \"b\": {\"t\": true, \"f\": false, \"n\": null},"
      " \"s\": \"x\\\"y\\\\z\\/\\b\\f\\n\\r\\t\", \"a\": 7}\n");
  ASSERT_TRUE(doc.ok()) << doc.status();
  ASSERT_TRUE(doc->is_object());
  ASSERT_EQ(doc->members.size(), 4u);
  const JsonValue* a = doc->Find("a");
  ASSERT_NE(a, nullptr);
  ASSERT_TRUE(a->is_array());
  ASSERT_EQ(a->items.size(), 3u) << "Find takes the first of repeated keys";
  EXPECT_EQ(a->items[0].number, 1.0);
  EXPECT_EQ(a->items[1].number, -2500.0);
  EXPECT_EQ(a->items[1].text, "-2.5e3");
  EXPECT_EQ(a->items[2].number, 0.125);
  const JsonValue* b = doc->Find("b");
  ASSERT_NE(b, nullptr);
  EXPECT_TRUE(b->Find("t")->boolean);
  EXPECT_EQ(b->Find("f")->type, JsonValue::Type::kBool);
  EXPECT_FALSE(b->Find("f")->boolean);
  EXPECT_EQ(b->Find("n")->type, JsonValue::Type::kNull);
  EXPECT_EQ(b->Find("missing"), nullptr);
  EXPECT_EQ(a->Find("a"), nullptr) << "an array has no members";
  EXPECT_EQ(doc->Find("s")->text, "x\"y\\z/\b\f\n\r\t");
}

TEST(JsonReaderTest, DecodesUnicodeEscapesToUtf8) {
  // U+00E9, U+20AC and U+1F600 (a surrogate pair), beside UTF-8 passed through.
  const absl::StatusOr<JsonValue> doc =
      ParseJson("\"\\u0041\\u00e9\\u20AC\\ud83d\\ude00 \xc3\xa9\"");
  ASSERT_TRUE(doc.ok()) << doc.status();
  EXPECT_EQ(doc->text, "A\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80 \xc3\xa9");
}

TEST(JsonReaderTest, ReadsWhatJsonWriterWrites) {
  JsonWriter json(2);
  json.BeginObject().Key("name\n\"q\"").String("tab\there").Key("n").Double(0.1);
  json.Key("list").BeginArray().Int(-3).Uint(18446744073709551615ull).Bool(true).Null();
  json.EndArray().EndObject();
  const absl::StatusOr<std::string> text = json.Finish();
  ASSERT_TRUE(text.ok()) << text.status();
  const absl::StatusOr<JsonValue> doc = ParseJson(*text);
  ASSERT_TRUE(doc.ok()) << doc.status() << "\n" << *text;
  EXPECT_EQ(doc->Find("name\n\"q\"")->text, "tab\there");
  EXPECT_EQ(doc->Find("n")->number, 0.1);
  const JsonValue& list = *doc->Find("list");
  ASSERT_EQ(list.items.size(), 4u);
  EXPECT_EQ(list.items[0].number, -3.0);
  EXPECT_EQ(list.items[1].text, "18446744073709551615");
  EXPECT_EQ(list.items[3].type, JsonValue::Type::kNull);
}

TEST(JsonReaderTest, RefusesWhatIsNotJsonAndSaysWhere) {
  struct Case {
    std::string text;
    std::string message;
  };
  const Case cases[] = {
      {"", "byte 0: expected a value"},
      {"   ", "byte 3: expected a value"},
      {"{\"a\":1,}", "byte 7: expected a string"},
      {"[1,]", "byte 3: expected a value"},
      {"[1 2]", "',' or ']' in an array"},
      {"{\"a\" 1}", "byte 5: expected ':'"},
      {"{\"a\":1", "',' or '}' in an object"},
      {"\"open", "the closing '\"' of a string"},
      {"\"a\nb\"", "byte 2: expected no control character"},
      {"\"\\x\"", "after a backslash"},
      {"\"\\u12\"", "four hex digits"},
      {"\"\\ud83d\"", "a low surrogate after a high one"},
      {"\"\\ude00\"", "a high surrogate before a low one"},
      {"01", "byte 1: expected the end of the document"},
      {"1.", "a digit after the decimal point"},
      {"1e+", "a digit in the exponent"},
      {"-", "byte 0: expected a value"},
      {"1e999", "a number within a double's range"},
      {"tru", "'true'"},
      {"nul", "'null'"},
      {"[1] [2]", "the end of the document"},
      {"// comment\n1", "byte 0: expected a value"},
  };
  for (const Case& c : cases) {
    const absl::StatusOr<JsonValue> doc = ParseJson(c.text);
    ASSERT_FALSE(doc.ok()) << "accepted: " << c.text;
    EXPECT_EQ(doc.status().code(), absl::StatusCode::kInvalidArgument) << c.text;
    EXPECT_THAT(doc.status().message(), HasSubstr(c.message)) << c.text;
  }
}

TEST(JsonReaderTest, NestingIsLimited) {
  const auto nested = [](int depth) {
    return absl::StrCat(std::string(depth, '['), std::string(depth, ']'));
  };
  EXPECT_TRUE(ParseJson(nested(kMaxJsonDepth)).ok());
  const absl::StatusOr<JsonValue> deep = ParseJson(nested(100000));
  ASSERT_FALSE(deep.ok());
  EXPECT_THAT(deep.status().message(), HasSubstr("nested arrays and objects"));
}

}  // namespace
}  // namespace neuralmesh

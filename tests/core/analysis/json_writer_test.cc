#include "core/analysis/json_writer.h"

#include <cmath>
#include <limits>
#include <string>

#include "gtest/gtest.h"
#include "core/analysis/json_reader.h"

namespace neuralmesh {
namespace {


TEST(JsonWriterTest, WritesCompactNestedDocument) {
  JsonWriter json;
  json.BeginObject();
  json.Key("name").String("bunny");
  json.Key("count").Uint(12);
  json.Key("delta").Int(-3);
  json.Key("ok").Bool(true);
  json.Key("nothing").Null();
  json.Key("list").BeginArray().Int(1).Int(2);
  json.BeginObject().EndObject();
  json.BeginArray().EndArray();
  json.EndArray();
  json.EndObject();
  const absl::StatusOr<std::string> text = json.Finish();
  ASSERT_TRUE(text.ok()) << "a well-formed sequence of calls was rejected: " << text.status();
  EXPECT_EQ(*text, R"({"name":"bunny","count":12,"delta":-3,"ok":true,"nothing":null,)"
                   R"("list":[1,2,{},[]]})")
      << "compact output differs from the expected text";
}

TEST(JsonWriterTest, IndentedOutputParsesToSameValues) {
  JsonWriter json(2);
  json.BeginObject();
  json.Key("a").BeginArray().Uint(1).Uint(2).EndArray();
  json.Key("b").String("x");
  json.EndObject();
  const absl::StatusOr<std::string> text = json.Finish();
  ASSERT_TRUE(text.ok()) << text.status();
  EXPECT_EQ(*text, "{\n  \"a\": [\n    1,\n    2\n  ],\n  \"b\": \"x\"\n}")
      << "indented layout differs from the expected text";
  const absl::StatusOr<JsonValue> parsed = ParseJson(*text);
  ASSERT_TRUE(parsed.ok())
      << "indented output is not valid JSON (" << parsed.status() << "): " << *text;
  ASSERT_NE(parsed->Find("a"), nullptr) << "member \"a\" lost";
  EXPECT_EQ(parsed->Find("a")->items.size(), 2u) << "array \"a\" lost elements";
}

TEST(JsonWriterTest, EscapesQuotesBackslashesAndControlCharacters) {
  const std::string nasty = std::string("q\"b\\s/n\nt\tr\rb\bf\fz") + '\x01' + "\x7f" +
                            "\xc3\xa9";  // UTF-8 e-acute passes through.
  EXPECT_EQ(JsonWriter::Quote(nasty), "\"q\\\"b\\\\s/n\\nt\\tr\\rb\\bf\\fz\\u0001\x7f\xc3\xa9\"")
      << "Quote() escaped something wrongly";
  JsonWriter json;
  json.BeginObject().Key(nasty).String(nasty).EndObject();
  const absl::StatusOr<std::string> text = json.Finish();
  ASSERT_TRUE(text.ok()) << text.status();
  const absl::StatusOr<JsonValue> parsed = ParseJson(*text);
  ASSERT_TRUE(parsed.ok())
      << "escaped output is not valid JSON (" << parsed.status() << "): " << *text;
  ASSERT_EQ(parsed->members.size(), 1u) << "expected one member";
  EXPECT_EQ(parsed->members[0].first, nasty) << "key did not round-trip";
  EXPECT_EQ(parsed->members[0].second.text, nasty) << "string value did not round-trip";
}

// A file name in Latin-1 (caf\xe9.obj) once went into `eval --json` as a raw byte, and the
// output was not valid UTF-8, so not JSON. Ill-formed bytes become U+FFFD; well-formed
// sequences of every length pass through.
TEST(JsonWriterTest, BytesThatAreNotUtf8BecomeTheReplacementCharacter) {
  EXPECT_EQ(JsonWriter::Quote("caf\xe9.obj"), "\"caf\\ufffd.obj\"");
  const std::string good = "\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80";  // e-acute, euro, emoji.
  EXPECT_EQ(JsonWriter::Quote(good), "\"" + good + "\"");
  // Overlong, a surrogate, above U+10FFFF, a lone continuation, a cut-off sequence.
  for (const std::string bad :
       {"\xc0\xaf", "\xed\xa0\x80", "\xf4\x90\x80\x80", "\x80", "\xe2\x82"}) {
    const std::string quoted = JsonWriter::Quote(bad);
    for (const char c : quoted) {
      EXPECT_LT(static_cast<unsigned char>(c), 0x80) << "a raw byte is left in " << quoted;
    }
    EXPECT_NE(quoted.find("\\ufffd"), std::string::npos) << quoted;
  }
}

TEST(JsonWriterTest, DoublesRoundTripAndNonFiniteBecomesNull) {
  const double values[] = {0.0,       1.0,    -2.5,          0.1,
                           1.0 / 3.0, 1e-300, 6.02214076e23, std::numeric_limits<double>::max()};
  JsonWriter json;
  json.BeginArray();
  for (double v : values) json.Double(v);
  json.Double(std::numeric_limits<double>::quiet_NaN());
  json.Double(std::numeric_limits<double>::infinity());
  json.EndArray();
  const absl::StatusOr<std::string> text = json.Finish();
  ASSERT_TRUE(text.ok()) << text.status();
  const absl::StatusOr<JsonValue> parsed = ParseJson(*text);
  ASSERT_TRUE(parsed.ok())
      << "double output is not valid JSON (" << parsed.status() << "): " << *text;
  const size_t n = sizeof(values) / sizeof(values[0]);
  ASSERT_EQ(parsed->items.size(), n + 2) << "wrong number of array elements in " << *text;
  for (size_t i = 0; i < n; ++i) {
    EXPECT_EQ(parsed->items[i].number, values[i])
        << "double " << i << " did not round-trip exactly: " << parsed->items[i].text;
  }
  EXPECT_EQ(parsed->items[1].text, "1") << "1.0 should print in its shortest form";
  EXPECT_EQ(parsed->items[3].text, "0.1") << "0.1 should print in its shortest form";
  EXPECT_EQ(parsed->items[n].type, JsonValue::Type::kNull) << "NaN must become null";
  EXPECT_EQ(parsed->items[n + 1].type, JsonValue::Type::kNull) << "inf must become null";
}

TEST(JsonWriterTest, TopLevelScalarIsADocument) {
  JsonWriter json;
  json.String("alone");
  const absl::StatusOr<std::string> text = json.Finish();
  ASSERT_TRUE(text.ok()) << "a lone scalar is valid JSON but was rejected: " << text.status();
  EXPECT_EQ(*text, "\"alone\"") << "lone scalar written wrongly";
}

TEST(JsonWriterTest, RejectsMisuse) {
  {
    JsonWriter json;
    json.BeginObject().Uint(1).EndObject();
    EXPECT_EQ(json.Finish().status().code(), absl::StatusCode::kFailedPrecondition)
        << "a value without a key inside an object was accepted";
  }
  {
    JsonWriter json;
    json.BeginArray().Key("k").Uint(1).EndArray();
    EXPECT_EQ(json.Finish().status().code(), absl::StatusCode::kFailedPrecondition)
        << "a key inside an array was accepted";
  }
  {
    JsonWriter json;
    json.BeginObject().Key("a").Key("b").Uint(1).EndObject();
    EXPECT_EQ(json.Finish().status().code(), absl::StatusCode::kFailedPrecondition)
        << "two keys in a row were accepted";
  }
  {
    JsonWriter json;
    json.BeginObject().Key("a").EndObject();
    EXPECT_EQ(json.Finish().status().code(), absl::StatusCode::kFailedPrecondition)
        << "a key without a value was accepted";
  }
  {
    JsonWriter json;
    json.BeginArray().EndObject();
    EXPECT_EQ(json.Finish().status().code(), absl::StatusCode::kFailedPrecondition)
        << "EndObject closing an array was accepted";
  }
  {
    JsonWriter json;
    json.BeginObject().EndObject().BeginObject().EndObject();
    EXPECT_EQ(json.Finish().status().code(), absl::StatusCode::kFailedPrecondition)
        << "two top-level values were accepted";
  }
  {
    JsonWriter json;
    json.BeginObject().Key("a").BeginArray();
    EXPECT_EQ(json.Finish().status().code(), absl::StatusCode::kFailedPrecondition)
        << "unclosed containers were accepted";
  }
  {
    JsonWriter json;
    EXPECT_EQ(json.Finish().status().code(), absl::StatusCode::kFailedPrecondition)
        << "an empty document was accepted";
  }
}

}  // namespace
}  // namespace neuralmesh

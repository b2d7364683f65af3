// A strict JSON reader (RFC 8259): the counterpart of JsonWriter, for formats that carry JSON
// (glTF) and for tests that check what the writers produce. No trailing commas, no comments;
// \u escapes, surrogate pairs included, are decoded to UTF-8.
//
// Usage:
//   absl::StatusOr<JsonValue> doc = ParseJson(R"({"asset":{"version":"2.0"}})");
//   const JsonValue* asset = doc->Find("asset");
#ifndef NEURALMESH_CORE_ANALYSIS_JSON_READER_H_
#define NEURALMESH_CORE_ANALYSIS_JSON_READER_H_

#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh {

struct JsonValue {
  enum class Type { kNull, kBool, kNumber, kString, kArray, kObject };
  Type type = Type::kNull;
  bool boolean = false;
  double number = 0.0;  // Nearest double to the number as written.
  std::string text;     // The string (UTF-8), or the number as written.
  std::vector<JsonValue> items;
  std::vector<std::pair<std::string, JsonValue>> members;  // In document order.

  bool is_number() const { return type == Type::kNumber; }
  bool is_string() const { return type == Type::kString; }
  bool is_array() const { return type == Type::kArray; }
  bool is_object() const { return type == Type::kObject; }

  // The first member named `key`, or nullptr (also when this is not an object).
  const JsonValue* Find(absl::string_view key) const;
};

// The deepest nesting of arrays and objects that ParseJson accepts.
inline constexpr int kMaxJsonDepth = 64;

// Parses `text`, which must hold exactly one JSON value (whitespace around it allowed).
// INVALID_ARGUMENT otherwise, with the byte offset and what was expected there; also for
// nesting deeper than kMaxJsonDepth, a lone surrogate escape, or a number outside a double's
// range.
absl::StatusOr<JsonValue> ParseJson(absl::string_view text);

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_JSON_READER_H_

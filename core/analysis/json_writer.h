// A tiny streaming JSON writer: objects, arrays, escaped strings, integers, booleans and
// shortest round-trip doubles, without an external JSON library. Used by the mesh report and
// by command-line tools that print machine-readable output.
//
// Usage:
//   JsonWriter json;
//   json.BeginObject().Key("vertices").Uint(12).Key("closed").Bool(true).EndObject();
//   absl::StatusOr<std::string> text = json.Finish();   // {"vertices":12,"closed":true}
//
// Misuse (a value where a key is expected, a key inside an array, mismatched End*, a second
// top-level value) is recorded: every later call is ignored and Finish() reports it.
#ifndef NEURALMESH_CORE_ANALYSIS_JSON_WRITER_H_
#define NEURALMESH_CORE_ANALYSIS_JSON_WRITER_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace neuralmesh {

class JsonWriter {
 public:
  // indent: 0 writes everything on one line; n > 0 puts each member and array element on its
  // own line, indented by n spaces per nesting level.
  explicit JsonWriter(int indent = 0) : indent_(indent < 0 ? 0 : indent) {}

  JsonWriter& BeginObject();
  JsonWriter& EndObject();
  JsonWriter& BeginArray();
  JsonWriter& EndArray();

  // The name of the next member; only valid directly inside an object.
  JsonWriter& Key(absl::string_view key);

  // Values: valid at the top level (once), inside an array, or after a Key().
  JsonWriter& String(absl::string_view value);  // UTF-8 is passed through, controls escaped.
  JsonWriter& Int(int64_t value);
  JsonWriter& Uint(uint64_t value);
  JsonWriter& Double(double value);  // Shortest round-trip form; NaN and infinities -> null.
  JsonWriter& Bool(bool value);
  JsonWriter& Null();

  // The document written so far, complete or not; for diagnostics.
  const std::string& text() const { return text_; }

  // Returns the document. FAILED_PRECONDITION when the calls did not form exactly one complete
  // JSON value (misuse, unclosed containers, or nothing written).
  absl::StatusOr<std::string> Finish() const;

  // `value` as a quoted JSON string literal: ", \ and control characters escaped, and each byte
  // that starts no well-formed UTF-8 sequence written as \ufffd (the replacement character).
  static std::string Quote(absl::string_view value);

 private:
  enum class Scope { kObject, kArray };
  struct Frame {
    Scope scope;
    bool empty = true;     // No member or element written yet.
    bool has_key = false;  // Inside an object: a key waits for its value.
  };

  // Checks that a value may start here and writes the separator before it.
  bool BeginValue();
  void NewLine(size_t depth);
  void Fail(absl::string_view message);

  int indent_;
  std::string text_;
  std::vector<Frame> stack_;
  bool done_ = false;  // A complete top-level value has been written.
  absl::Status status_;
};

}  // namespace neuralmesh

#endif  // NEURALMESH_CORE_ANALYSIS_JSON_WRITER_H_

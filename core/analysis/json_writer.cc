#include "core/analysis/json_writer.h"

#include <charconv>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace neuralmesh {
namespace {

// The length of the well-formed UTF-8 sequence that starts at value[i] (RFC 3629: no overlong
// forms, no surrogates, nothing above U+10FFFF), or 0 when none does. Requires value[i] >= 0x80.
size_t Utf8SequenceLength(absl::string_view value, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(value[k]); };
  const unsigned char lead = byte(i);
  size_t length = 0;
  unsigned char second_min = 0x80, second_max = 0xbf;
  if (lead >= 0xc2 && lead <= 0xdf) {
    length = 2;
  } else if (lead >= 0xe0 && lead <= 0xef) {
    length = 3;
    if (lead == 0xe0) second_min = 0xa0;
    if (lead == 0xed) second_max = 0x9f;
  } else if (lead >= 0xf0 && lead <= 0xf4) {
    length = 4;
    if (lead == 0xf0) second_min = 0x90;
    if (lead == 0xf4) second_max = 0x8f;
  } else {
    return 0;
  }
  if (value.size() - i < length) return 0;
  if (byte(i + 1) < second_min || byte(i + 1) > second_max) return 0;
  for (size_t k = i + 2; k < i + length; ++k) {
    if (byte(k) < 0x80 || byte(k) > 0xbf) return 0;
  }
  return length;
}

}  // namespace

std::string JsonWriter::Quote(absl::string_view value) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(value.size() + 2);
  out.push_back('"');
  for (size_t i = 0; i < value.size(); ++i) {
    const char ch = value[i];
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c >= 0x80) {
      // JSON text is UTF-8: a byte that starts no well-formed sequence (a file name in
      // Latin-1, say) becomes U+FFFD, the replacement character, instead of invalid output.
      const size_t length = Utf8SequenceLength(value, i);
      if (length == 0) {
        out += "\\ufffd";
      } else {
        out.append(value.data() + i, length);
        i += length - 1;
      }
      continue;
    }
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20) {
          out += "\\u00";
          out.push_back(kHex[c >> 4]);
          out.push_back(kHex[c & 0xf]);
        } else {
          out.push_back(ch);
        }
    }
  }
  out.push_back('"');
  return out;
}

void JsonWriter::Fail(absl::string_view message) {
  if (!status_.ok()) return;
  // The end of the document is enough context to find the faulty call.
  constexpr size_t kContext = 60;
  const absl::string_view written(text_);
  const absl::string_view tail =
      written.size() > kContext ? written.substr(written.size() - kContext) : written;
  status_ = absl::FailedPreconditionError(absl::StrCat(
      "JsonWriter: ", message, " after \"", written.size() > kContext ? "..." : "", tail, "\""));
}

void JsonWriter::NewLine(size_t depth) {
  if (indent_ == 0) return;
  text_.push_back('\n');
  text_.append(depth * static_cast<size_t>(indent_), ' ');
}

bool JsonWriter::BeginValue() {
  if (!status_.ok()) return false;
  if (stack_.empty()) {
    if (done_) {
      Fail("a second top-level value");
      return false;
    }
    return true;
  }
  Frame& frame = stack_.back();
  if (frame.scope == Scope::kObject) {
    if (!frame.has_key) {
      Fail("a value without a key inside an object");
      return false;
    }
    frame.has_key = false;
    return true;
  }
  if (!frame.empty) text_.push_back(',');
  frame.empty = false;
  NewLine(stack_.size());
  return true;
}

JsonWriter& JsonWriter::Key(absl::string_view key) {
  if (!status_.ok()) return *this;
  if (stack_.empty() || stack_.back().scope != Scope::kObject) {
    Fail("a key outside an object");
    return *this;
  }
  Frame& frame = stack_.back();
  if (frame.has_key) {
    Fail("two keys in a row");
    return *this;
  }
  if (!frame.empty) text_.push_back(',');
  frame.empty = false;
  frame.has_key = true;
  NewLine(stack_.size());
  text_ += Quote(key);
  text_ += indent_ > 0 ? ": " : ":";
  return *this;
}

JsonWriter& JsonWriter::BeginObject() {
  if (!BeginValue()) return *this;
  text_.push_back('{');
  stack_.push_back({Scope::kObject});
  return *this;
}

JsonWriter& JsonWriter::BeginArray() {
  if (!BeginValue()) return *this;
  text_.push_back('[');
  stack_.push_back({Scope::kArray});
  return *this;
}

JsonWriter& JsonWriter::EndObject() {
  if (!status_.ok()) return *this;
  if (stack_.empty() || stack_.back().scope != Scope::kObject) {
    Fail("EndObject without a matching BeginObject");
    return *this;
  }
  if (stack_.back().has_key) {
    Fail("EndObject right after a key");
    return *this;
  }
  const bool empty = stack_.back().empty;
  stack_.pop_back();
  if (!empty) NewLine(stack_.size());
  text_.push_back('}');
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::EndArray() {
  if (!status_.ok()) return *this;
  if (stack_.empty() || stack_.back().scope != Scope::kArray) {
    Fail("EndArray without a matching BeginArray");
    return *this;
  }
  const bool empty = stack_.back().empty;
  stack_.pop_back();
  if (!empty) NewLine(stack_.size());
  text_.push_back(']');
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::String(absl::string_view value) {
  if (!BeginValue()) return *this;
  text_ += Quote(value);
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::Int(int64_t value) {
  if (!BeginValue()) return *this;
  absl::StrAppend(&text_, value);
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::Uint(uint64_t value) {
  if (!BeginValue()) return *this;
  absl::StrAppend(&text_, value);
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::Double(double value) {
  if (!BeginValue()) return *this;
  if (!std::isfinite(value)) {
    // JSON has no NaN or infinity.
    text_ += "null";
  } else {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    text_.append(buffer, result.ptr);
  }
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::Bool(bool value) {
  if (!BeginValue()) return *this;
  text_ += value ? "true" : "false";
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::Null() {
  if (!BeginValue()) return *this;
  text_ += "null";
  if (stack_.empty()) done_ = true;
  return *this;
}

absl::StatusOr<std::string> JsonWriter::Finish() const {
  if (!status_.ok()) return status_;
  if (!stack_.empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("JsonWriter: ", stack_.size(), " unclosed object(s) or array(s)"));
  }
  if (!done_) return absl::FailedPreconditionError("JsonWriter: nothing written");
  return text_;
}

}  // namespace neuralmesh

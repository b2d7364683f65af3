#include "core/analysis/json_reader.h"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"

namespace neuralmesh {
namespace {

class JsonParser {
 public:
  explicit JsonParser(absl::string_view text) : s_(text) {}

  absl::StatusOr<JsonValue> ParseDocument() {
    JsonValue value;
    if (!ParseValue(value, 0)) return error_;
    SkipSpace();
    if (pos_ != s_.size()) {
      Fail("the end of the document after its value");
      return error_;
    }
    return value;
  }

 private:
  // Records what was expected at the current offset; returns false for the callers to pass on.
  bool Fail(absl::string_view expected) {
    if (error_.ok()) {
      error_ =
          absl::InvalidArgumentError(absl::StrCat("JSON byte ", pos_, ": expected ", expected));
    }
    return false;
  }

  void SkipSpace() {
    while (pos_ < s_.size() &&
           (s_[pos_] == ' ' || s_[pos_] == '\n' || s_[pos_] == '\t' || s_[pos_] == '\r')) {
      ++pos_;
    }
  }

  bool Consume(char c) {
    SkipSpace();
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }

  bool Expect(char c) { return Consume(c) || Fail(absl::StrCat("'", std::string(1, c), "'")); }

  bool Literal(absl::string_view word) {
    if (s_.substr(pos_, word.size()) != word) return Fail(absl::StrCat("'", word, "'"));
    pos_ += word.size();
    return true;
  }

  // Four hex digits at pos_.
  bool ReadHex4(uint32_t* code) {
    if (pos_ + 4 > s_.size()) return Fail("four hex digits after \\u");
    *code = 0;
    for (int i = 0; i < 4; ++i) {
      const char h = s_[pos_ + i];
      if (!absl::ascii_isxdigit(static_cast<unsigned char>(h))) {
        return Fail("four hex digits after \\u");
      }
      *code = *code * 16 +
              static_cast<uint32_t>(absl::ascii_isdigit(h) ? h - '0' : (h | 0x20) - 'a' + 10);
    }
    pos_ += 4;
    return true;
  }

  static void AppendUtf8(uint32_t code, std::string& out) {
    if (code < 0x80) {
      out.push_back(static_cast<char>(code));
    } else if (code < 0x800) {
      out.push_back(static_cast<char>(0xC0 | (code >> 6)));
      out.push_back(static_cast<char>(0x80 | (code & 0x3F)));
    } else if (code < 0x10000) {
      out.push_back(static_cast<char>(0xE0 | (code >> 12)));
      out.push_back(static_cast<char>(0x80 | ((code >> 6) & 0x3F)));
      out.push_back(static_cast<char>(0x80 | (code & 0x3F)));
    } else {
      out.push_back(static_cast<char>(0xF0 | (code >> 18)));
      out.push_back(static_cast<char>(0x80 | ((code >> 12) & 0x3F)));
      out.push_back(static_cast<char>(0x80 | ((code >> 6) & 0x3F)));
      out.push_back(static_cast<char>(0x80 | (code & 0x3F)));
    }
  }

  bool ParseEscape(std::string& out) {
    if (pos_ >= s_.size()) return Fail("an escaped character");
    const char e = s_[pos_++];
    switch (e) {
      case '"':
      case '\\':
      case '/':
        out.push_back(e);
        return true;
      case 'b':
        out.push_back('\b');
        return true;
      case 'f':
        out.push_back('\f');
        return true;
      case 'n':
        out.push_back('\n');
        return true;
      case 'r':
        out.push_back('\r');
        return true;
      case 't':
        out.push_back('\t');
        return true;
      case 'u':
        break;
      default:
        --pos_;
        return Fail("one of \" \\ / b f n r t u after a backslash");
    }
    uint32_t code;
    if (!ReadHex4(&code)) return false;
    if (code >= 0xDC00 && code <= 0xDFFF) return Fail("a high surrogate before a low one");
    if (code >= 0xD800 && code <= 0xDBFF) {
      uint32_t low;
      if (s_.substr(pos_, 2) != "\\u") return Fail("a low surrogate after a high one");
      pos_ += 2;
      if (!ReadHex4(&low)) return false;
      if (low < 0xDC00 || low > 0xDFFF) return Fail("a low surrogate after a high one");
      code = 0x10000 + ((code - 0xD800) << 10) + (low - 0xDC00);
    }
    AppendUtf8(code, out);
    return true;
  }

  bool ParseString(std::string& out) {
    if (pos_ >= s_.size() || s_[pos_] != '"') return Fail("a string");
    ++pos_;
    while (pos_ < s_.size()) {
      const unsigned char c = static_cast<unsigned char>(s_[pos_++]);
      if (c == '"') return true;
      if (c < 0x20) {
        --pos_;
        return Fail("no control character inside a string");
      }
      if (c != '\\') {
        out.push_back(static_cast<char>(c));
      } else if (!ParseEscape(out)) {
        return false;
      }
    }
    return Fail("the closing '\"' of a string");
  }

  size_t Digits() {
    const size_t from = pos_;
    while (pos_ < s_.size() && absl::ascii_isdigit(static_cast<unsigned char>(s_[pos_]))) ++pos_;
    return pos_ - from;
  }

  bool ParseNumber(JsonValue& out) {
    const size_t start = pos_;
    if (pos_ < s_.size() && s_[pos_] == '-') ++pos_;
    if (pos_ < s_.size() && s_[pos_] == '0') {
      ++pos_;
    } else if (Digits() == 0) {
      pos_ = start;
      return Fail("a value");
    }
    if (pos_ < s_.size() && s_[pos_] == '.') {
      ++pos_;
      if (Digits() == 0) return Fail("a digit after the decimal point");
    }
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      ++pos_;
      if (pos_ < s_.size() && (s_[pos_] == '+' || s_[pos_] == '-')) ++pos_;
      if (Digits() == 0) return Fail("a digit in the exponent");
    }
    out.type = JsonValue::Type::kNumber;
    out.text = std::string(s_.substr(start, pos_ - start));
    errno = 0;
    out.number = std::strtod(out.text.c_str(), nullptr);
    if (!std::isfinite(out.number)) {
      pos_ = start;
      return Fail("a number within a double's range");
    }
    return true;
  }

  bool ParseValue(JsonValue& out, int depth) {
    SkipSpace();
    if (pos_ >= s_.size()) return Fail("a value");
    const char c = s_[pos_];
    if (c == '{' || c == '[') {
      if (depth >= kMaxJsonDepth) {
        return Fail(absl::StrCat("no more than ", kMaxJsonDepth, " nested arrays and objects"));
      }
      ++pos_;
      return c == '{' ? ParseObject(out, depth) : ParseArray(out, depth);
    }
    if (c == '"') {
      out.type = JsonValue::Type::kString;
      return ParseString(out.text);
    }
    if (c == 't' || c == 'f') {
      out.type = JsonValue::Type::kBool;
      out.boolean = c == 't';
      return Literal(c == 't' ? "true" : "false");
    }
    if (c == 'n') {
      out.type = JsonValue::Type::kNull;
      return Literal("null");
    }
    return ParseNumber(out);
  }

  bool ParseObject(JsonValue& out, int depth) {
    out.type = JsonValue::Type::kObject;
    if (Consume('}')) return true;
    do {
      SkipSpace();
      std::string key;
      if (!ParseString(key) || !Expect(':')) return false;
      JsonValue value;
      if (!ParseValue(value, depth + 1)) return false;
      out.members.emplace_back(std::move(key), std::move(value));
    } while (Consume(','));
    return Consume('}') || Fail("',' or '}' in an object");
  }

  bool ParseArray(JsonValue& out, int depth) {
    out.type = JsonValue::Type::kArray;
    if (Consume(']')) return true;
    do {
      JsonValue value;
      if (!ParseValue(value, depth + 1)) return false;
      out.items.push_back(std::move(value));
    } while (Consume(','));
    return Consume(']') || Fail("',' or ']' in an array");
  }

  absl::string_view s_;
  size_t pos_ = 0;
  absl::Status error_;
};

}  // namespace

const JsonValue* JsonValue::Find(absl::string_view key) const {
  for (const auto& [name, value] : members) {
    if (name == key) return &value;
  }
  return nullptr;
}

absl::StatusOr<JsonValue> ParseJson(absl::string_view text) {
  return JsonParser(text).ParseDocument();
}

}  // namespace neuralmesh

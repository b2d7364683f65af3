// A minimal strict JSON parser for tests that check the output of JsonWriter and its users.
// Accepts exactly RFC 8259 syntax (no trailing commas, no comments); \u escapes are decoded
// for code points below 0x80 only, which is all our writers emit.
#ifndef NEURALMESH_TESTS_CORE_ANALYSIS_JSON_PARSE_FOR_TEST_H_
#define NEURALMESH_TESTS_CORE_ANALYSIS_JSON_PARSE_FOR_TEST_H_

#include <cctype>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace neuralmesh::testing {

struct JsonValue {
  enum class Type { kNull, kBool, kNumber, kString, kArray, kObject };
  Type type = Type::kNull;
  bool boolean = false;
  double number = 0.0;
  std::string text;  // The string, or the number as written.
  std::vector<JsonValue> items;
  std::vector<std::pair<std::string, JsonValue>> members;  // In document order.

  // The member named `key`, or nullptr.
  const JsonValue* Find(const std::string& key) const {
    for (const auto& [name, value] : members) {
      if (name == key) return &value;
    }
    return nullptr;
  }
};

class JsonTestParser {
 public:
  // The parsed document, or nullopt when `text` is not exactly one JSON value.
  static std::optional<JsonValue> Parse(const std::string& text) {
    JsonTestParser parser(text);
    JsonValue value;
    parser.SkipSpace();
    if (!parser.ParseValue(value, 0)) return std::nullopt;
    parser.SkipSpace();
    if (parser.pos_ != text.size()) return std::nullopt;
    return value;
  }

 private:
  explicit JsonTestParser(const std::string& text) : s_(text) {}

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
  bool Literal(const char* word) {
    const std::string w(word);
    if (s_.compare(pos_, w.size(), w) != 0) return false;
    pos_ += w.size();
    return true;
  }
  bool ParseString(std::string& out) {
    if (pos_ >= s_.size() || s_[pos_] != '"') return false;
    ++pos_;
    while (pos_ < s_.size()) {
      const unsigned char c = static_cast<unsigned char>(s_[pos_++]);
      if (c == '"') return true;
      if (c < 0x20) return false;
      if (c != '\\') {
        out.push_back(static_cast<char>(c));
        continue;
      }
      if (pos_ >= s_.size()) return false;
      const char e = s_[pos_++];
      switch (e) {
        case '"':
          out.push_back('"');
          break;
        case '\\':
          out.push_back('\\');
          break;
        case '/':
          out.push_back('/');
          break;
        case 'b':
          out.push_back('\b');
          break;
        case 'f':
          out.push_back('\f');
          break;
        case 'n':
          out.push_back('\n');
          break;
        case 'r':
          out.push_back('\r');
          break;
        case 't':
          out.push_back('\t');
          break;
        case 'u': {
          if (pos_ + 4 > s_.size()) return false;
          const std::string hex = s_.substr(pos_, 4);
          for (char h : hex) {
            if (!std::isxdigit(static_cast<unsigned char>(h))) return false;
          }
          const long code = std::strtol(hex.c_str(), nullptr, 16);
          if (code >= 0x80) return false;
          out.push_back(static_cast<char>(code));
          pos_ += 4;
          break;
        }
        default:
          return false;
      }
    }
    return false;
  }
  bool ParseNumber(JsonValue& out) {
    const size_t start = pos_;
    if (pos_ < s_.size() && s_[pos_] == '-') ++pos_;
    auto digits = [&] {
      const size_t from = pos_;
      while (pos_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_]))) ++pos_;
      return pos_ - from;
    };
    if (pos_ < s_.size() && s_[pos_] == '0') {
      ++pos_;
    } else if (digits() == 0) {
      return false;
    }
    if (pos_ < s_.size() && s_[pos_] == '.') {
      ++pos_;
      if (digits() == 0) return false;
    }
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      ++pos_;
      if (pos_ < s_.size() && (s_[pos_] == '+' || s_[pos_] == '-')) ++pos_;
      if (digits() == 0) return false;
    }
    out.type = JsonValue::Type::kNumber;
    out.text = s_.substr(start, pos_ - start);
    out.number = std::strtod(out.text.c_str(), nullptr);
    return true;
  }
  bool ParseValue(JsonValue& out, int depth) {
    if (depth > 64) return false;
    SkipSpace();
    if (pos_ >= s_.size()) return false;
    const char c = s_[pos_];
    if (c == '{') {
      ++pos_;
      out.type = JsonValue::Type::kObject;
      if (Consume('}')) return true;
      do {
        SkipSpace();
        std::string key;
        if (!ParseString(key) || !Consume(':')) return false;
        JsonValue value;
        if (!ParseValue(value, depth + 1)) return false;
        out.members.emplace_back(std::move(key), std::move(value));
      } while (Consume(','));
      return Consume('}');
    }
    if (c == '[') {
      ++pos_;
      out.type = JsonValue::Type::kArray;
      if (Consume(']')) return true;
      do {
        JsonValue value;
        if (!ParseValue(value, depth + 1)) return false;
        out.items.push_back(std::move(value));
      } while (Consume(','));
      return Consume(']');
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

  const std::string& s_;
  size_t pos_ = 0;
};

}  // namespace neuralmesh::testing

#endif  // NEURALMESH_TESTS_CORE_ANALYSIS_JSON_PARSE_FOR_TEST_H_

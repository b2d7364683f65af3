#include "core/io/internal/xml.h"

#include <cstdint>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "core/io/internal/text.h"

namespace neuralmesh::io_internal {
namespace {

bool IsNameChar(char c) {
  return absl::ascii_isalnum(static_cast<unsigned char>(c)) || c == '_' || c == ':' || c == '-' ||
         c == '.' || static_cast<unsigned char>(c) >= 0x80;
}

// Appends code point `code` in UTF-8.
void AppendUtf8(uint32_t code, std::string* out) {
  if (code < 0x80) {
    out->push_back(static_cast<char>(code));
  } else if (code < 0x800) {
    out->push_back(static_cast<char>(0xC0 | code >> 6));
    out->push_back(static_cast<char>(0x80 | (code & 0x3F)));
  } else if (code < 0x10000) {
    out->push_back(static_cast<char>(0xE0 | code >> 12));
    out->push_back(static_cast<char>(0x80 | (code >> 6 & 0x3F)));
    out->push_back(static_cast<char>(0x80 | (code & 0x3F)));
  } else {
    out->push_back(static_cast<char>(0xF0 | code >> 18));
    out->push_back(static_cast<char>(0x80 | (code >> 12 & 0x3F)));
    out->push_back(static_cast<char>(0x80 | (code >> 6 & 0x3F)));
    out->push_back(static_cast<char>(0x80 | (code & 0x3F)));
  }
}

class XmlParser {
 public:
  explicit XmlParser(absl::string_view document) : in_(document) {
    if (absl::StartsWith(in_, "\xEF\xBB\xBF")) at_ = 3;  // UTF-8's byte order mark.
  }

  absl::StatusOr<XmlElement> Parse() {
    std::vector<XmlElement> open;  // The elements begun and not yet ended, outermost first.
    bool have_root = false;
    XmlElement root;
    while (at_ < in_.size()) {
      if (in_[at_] != '<') {
        const size_t end = std::min(in_.find('<', at_), in_.size());
        const absl::string_view text = in_.substr(at_, end - at_);
        if (open.empty()) {
          if (!absl::StripAsciiWhitespace(text).empty()) {
            return Error(have_root ? "text after the root element"
                                   : "text before the root element");
          }
        } else {
          absl::Status decoded = Decode(text, &open.back().text);
          if (!decoded.ok()) return decoded;
        }
        Advance(end);
        continue;
      }
      const absl::string_view rest = in_.substr(at_);
      if (absl::StartsWith(rest, "<?")) {
        if (!SkipPast("?>")) return Error("a processing instruction without its '?>'");
      } else if (absl::StartsWith(rest, "<!--")) {
        if (!SkipPast("-->")) return Error("a comment without its '-->'");
      } else if (absl::StartsWith(rest, "<![CDATA[")) {
        if (open.empty()) return Error("a CDATA section outside the root element");
        const size_t end = in_.find("]]>", at_ + 9);
        if (end == absl::string_view::npos) return Error("a CDATA section without its ']]>'");
        open.back().text.append(in_.data() + at_ + 9, end - at_ - 9);
        Advance(end + 3);
      } else if (absl::StartsWith(rest, "<!")) {
        return Error("document type declarations are not supported");
      } else if (absl::StartsWith(rest, "</")) {
        Advance(at_ + 2);
        const absl::string_view name = ReadName();
        SkipSpace();
        if (name.empty() || at_ >= in_.size() || in_[at_] != '>') {
          return Error("a malformed end tag");
        }
        ++at_;
        if (open.empty() || open.back().name != name) {
          return Error(absl::StrCat("end tag </", name, "> where ",
                                    open.empty() ? std::string("no element is open")
                                                 : absl::StrCat("<", open.back().name, "> ends")));
        }
        XmlElement done = std::move(open.back());
        open.pop_back();
        if (open.empty()) {
          root = std::move(done);
          have_root = true;
        } else {
          open.back().children.push_back(std::move(done));
        }
      } else {
        if (open.empty() && have_root) return Error("a second root element");
        if (open.size() >= static_cast<size_t>(kMaxXmlDepth)) {
          return Error(absl::StrCat("elements nested more than ", kMaxXmlDepth, " deep"));
        }
        XmlElement element;
        bool empty = false;
        absl::Status tag = ReadStartTag(&element, &empty);
        if (!tag.ok()) return tag;
        if (!empty) {
          open.push_back(std::move(element));
        } else if (open.empty()) {
          root = std::move(element);
          have_root = true;
        } else {
          open.back().children.push_back(std::move(element));
        }
      }
    }
    if (!open.empty()) {
      return Error(absl::StrCat("the document ends inside <", open.back().name, ">"));
    }
    if (!have_root) return Error("no root element");
    return root;
  }

 private:
  absl::Status Error(absl::string_view what) const { return LineError(line_, what); }

  // Moves to offset `to`, counting the lines passed.
  void Advance(size_t to) {
    for (; at_ < to; ++at_) line_ += in_[at_] == '\n';
  }

  bool SkipPast(absl::string_view end) {
    const size_t found = in_.find(end, at_);
    if (found == absl::string_view::npos) return false;
    Advance(found + end.size());
    return true;
  }

  void SkipSpace() {
    while (at_ < in_.size() && absl::ascii_isspace(static_cast<unsigned char>(in_[at_]))) {
      Advance(at_ + 1);
    }
  }

  absl::string_view ReadName() {
    const size_t begin = at_;
    while (at_ < in_.size() && IsNameChar(in_[at_])) ++at_;
    return in_.substr(begin, at_ - begin);
  }

  // At '<' of a start tag: reads its name and attributes, through '>' or "/>" (`empty`).
  absl::Status ReadStartTag(XmlElement* element, bool* empty) {
    ++at_;
    element->name = std::string(ReadName());
    if (element->name.empty()) return Error("a '<' that begins no tag");
    while (true) {
      const size_t before = at_;
      SkipSpace();
      if (at_ >= in_.size()) return Error(absl::StrCat("the tag <", element->name, " never ends"));
      if (in_[at_] == '>') {
        ++at_;
        return absl::OkStatus();
      }
      if (absl::StartsWith(in_.substr(at_), "/>")) {
        at_ += 2;
        *empty = true;
        return absl::OkStatus();
      }
      if (at_ == before) {
        return Error(
            absl::StrCat("the tag <", element->name, "> lacks a space before an attribute"));
      }
      const absl::string_view name = ReadName();
      SkipSpace();
      if (name.empty() || at_ >= in_.size() || in_[at_] != '=') {
        return Error(absl::StrCat("a malformed attribute in <", element->name, ">"));
      }
      Advance(at_ + 1);
      SkipSpace();
      if (at_ >= in_.size() || (in_[at_] != '"' && in_[at_] != '\'')) {
        return Error(
            absl::StrCat("attribute ", name, " of <", element->name, "> has no quoted value"));
      }
      const char quote = in_[at_];
      const size_t end = in_.find(quote, at_ + 1);
      if (end == absl::string_view::npos) {
        return Error(absl::StrCat("attribute ", name, "'s value never ends"));
      }
      std::string value;
      absl::Status decoded = Decode(in_.substr(at_ + 1, end - at_ - 1), &value);
      if (!decoded.ok()) return decoded;
      for (const auto& [existing, unused] : element->attributes) {
        if (existing == name) {
          return Error(absl::StrCat("attribute ", name, " twice in <", element->name, ">"));
        }
      }
      element->attributes.emplace_back(std::string(name), std::move(value));
      Advance(end + 1);
    }
  }

  // Appends `text` to `out` with its entity and character references replaced.
  absl::Status Decode(absl::string_view text, std::string* out) const {
    size_t i = 0;
    while (i < text.size()) {
      const size_t amp = text.find('&', i);
      if (amp == absl::string_view::npos) {
        out->append(text.data() + i, text.size() - i);
        break;
      }
      out->append(text.data() + i, amp - i);
      const size_t semi = text.find(';', amp);
      if (semi == absl::string_view::npos || semi - amp > 12) {
        return Error("an '&' that begins no entity");
      }
      const absl::string_view entity = text.substr(amp + 1, semi - amp - 1);
      if (entity == "lt") {
        out->push_back('<');
      } else if (entity == "gt") {
        out->push_back('>');
      } else if (entity == "amp") {
        out->push_back('&');
      } else if (entity == "quot") {
        out->push_back('"');
      } else if (entity == "apos") {
        out->push_back('\'');
      } else if (absl::StartsWith(entity, "#")) {
        uint32_t code = 0;
        const bool hex = absl::StartsWith(entity, "#x");
        const bool parsed = hex ? absl::SimpleHexAtoi(entity.substr(2), &code)
                                : absl::SimpleAtoi(entity.substr(1), &code);
        if (!parsed || code == 0 || code > 0x10FFFF) {
          return Error(absl::StrCat("character reference &", entity, "; is not a character"));
        }
        AppendUtf8(code, out);
      } else {
        return Error(absl::StrCat("undefined entity &", Quoted(entity), ";"));
      }
      i = semi + 1;
    }
    return absl::OkStatus();
  }

  absl::string_view in_;
  size_t at_ = 0;
  int line_ = 1;
};

}  // namespace

const XmlElement* XmlElement::Child(absl::string_view child_name) const {
  for (const XmlElement& child : children) {
    if (child.name == child_name) return &child;
  }
  return nullptr;
}

const std::string* XmlElement::Attribute(absl::string_view attribute_name) const {
  for (const auto& [name, value] : attributes) {
    if (name == attribute_name) return &value;
  }
  return nullptr;
}

absl::StatusOr<XmlElement> ParseXml(absl::string_view document) {
  return XmlParser(document).Parse();
}

std::string EscapeXml(absl::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out.push_back(c);
    }
  }
  return out;
}

}  // namespace neuralmesh::io_internal

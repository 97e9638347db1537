#include "io/XmlPullParser.h"

#include <charconv>
#include <cstdio>

#include "tessera/core/Error.h"

namespace tessera::io_detail {

namespace {

// VTK's markup is a handful of short elements; these bounds are far above
// anything it writes and far below what would let a file cost memory.
constexpr std::size_t kBufferBytes = 64 * 1024;
constexpr std::size_t kMaxNameBytes = 256;
constexpr std::size_t kMaxAttributeBytes = 1 << 20;
constexpr std::size_t kMaxAttributes = 256;
constexpr std::size_t kMaxDepth = 64;
constexpr std::size_t kMaxDeclarationBytes = 64 * 1024;

bool isSpace(int c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}
bool isNameStart(int c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_' || c == ':';
}
bool isNameChar(int c) {
  return isNameStart(c) || (c >= '0' && c <= '9') || c == '-' || c == '.';
}

std::string shown(int c) {
  if (c < 0) return "the end of the file";
  if (c >= 0x20 && c < 0x7f) return std::string("'") + static_cast<char>(c) + "'";
  char buf[16];
  std::snprintf(buf, sizeof buf, "byte 0x%02x", static_cast<unsigned>(c));
  return buf;
}

// UTF-8 for a character reference (&#...;).
void appendUtf8(std::string& out, std::uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xc0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3f));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xe0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3f));
    out += static_cast<char>(0x80 | (cp & 0x3f));
  } else {
    out += static_cast<char>(0xf0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3f));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3f));
    out += static_cast<char>(0x80 | (cp & 0x3f));
  }
}

}  // namespace

const std::string* XmlEvent::attribute(std::string_view attributeName) const {
  for (const auto& a : attributes) {
    if (a.name == attributeName) return &a.value;
  }
  return nullptr;
}

XmlPullParser::XmlPullParser(const ByteSource& file)
    : what_(file.name()), file_(file, 0), buf_(kBufferBytes) {
  // A UTF-8 byte order mark is allowed before the first '<'.
  if (peek() == 0xef) {
    const unsigned char bom[3] = {0xef, 0xbb, 0xbf};
    if (len_ >= 3 && buf_[0] == bom[0] && buf_[1] == bom[1] && buf_[2] == bom[2]) {
      pos_ = 3;
      offset_ = 3;
    }
  }
}

void XmlPullParser::fail(const std::string& msg) const {
  failAt(line_, msg);
}

void XmlPullParser::failAt(int line, const std::string& msg) const {
  throw InputError(what_ + ": line " + std::to_string(line) + ": " + msg);
}

bool XmlPullParser::refill() {
  if (eof_) return false;
  len_ = file_.read(reinterpret_cast<std::byte*>(buf_.data()), buf_.size());
  pos_ = 0;
  if (len_ == 0) eof_ = true;
  return len_ > 0;
}

int XmlPullParser::peek() {
  if (pos_ == len_ && !refill()) return -1;
  return buf_[pos_];
}

int XmlPullParser::get() {
  const int c = peek();
  if (c < 0) return c;
  ++pos_;
  ++offset_;
  if (c == '\n') ++line_;
  return c;
}

void XmlPullParser::expect(char c, const char* where) {
  const int got = get();
  if (got != c) {
    fail(std::string("expected '") + c + "' " + where + ", found " + shown(got));
  }
}

void XmlPullParser::skipSpace() {
  while (isSpace(peek())) get();
}

std::string XmlPullParser::readName(const char* what) {
  const int first = peek();
  if (!isNameStart(first)) fail(std::string("expected ") + what + ", found " + shown(first));
  std::string name;
  while (isNameChar(peek())) {
    if (name.size() >= kMaxNameBytes) {
      fail(std::string(what) + " '" + name.substr(0, 40) + "...' is longer than " +
           std::to_string(kMaxNameBytes) + " bytes");
    }
    name += static_cast<char>(get());
  }
  return name;
}

std::string XmlPullParser::readAttributeValue(const std::string& attributeName) {
  const int quote = get();
  if (quote != '"' && quote != '\'') {
    fail("value of attribute '" + attributeName + "' must be quoted, found " + shown(quote));
  }
  const int startLine = line_;
  std::string value;
  while (true) {
    const int c = get();
    if (c < 0) {
      failAt(startLine,
             "unterminated XML: the value of attribute '" + attributeName + "' is never closed");
    }
    if (c == quote) break;
    if (c == '<') fail("'<' inside the value of attribute '" + attributeName + "'");
    if (value.size() >= kMaxAttributeBytes) {
      failAt(startLine, "value of attribute '" + attributeName + "' is longer than " +
                            std::to_string(kMaxAttributeBytes) + " bytes");
    }
    if (c != '&') {
      value += static_cast<char>(c);
      continue;
    }
    std::string ref;
    while (true) {
      const int r = get();
      if (r == ';') break;
      if (r < 0 || ref.size() > 10 || isSpace(r) || r == quote) {
        fail("unterminated entity reference '&" + ref + "' in attribute '" + attributeName + "'");
      }
      ref += static_cast<char>(r);
    }
    if (ref == "lt") {
      value += '<';
    } else if (ref == "gt") {
      value += '>';
    } else if (ref == "amp") {
      value += '&';
    } else if (ref == "quot") {
      value += '"';
    } else if (ref == "apos") {
      value += '\'';
    } else if (ref.size() > 1 && ref[0] == '#') {
      const bool hex = ref[1] == 'x';
      const char* b = ref.data() + (hex ? 2 : 1);
      const char* e = ref.data() + ref.size();
      std::uint32_t cp = 0;
      const auto [ptr, ec] = std::from_chars(b, e, cp, hex ? 16 : 10);
      if (ec != std::errc() || ptr != e || b == e || cp == 0 || cp > 0x10ffff) {
        fail("bad character reference '&" + ref + ";' in attribute '" + attributeName + "'");
      }
      appendUtf8(value, cp);
    } else {
      fail("unknown entity '&" + ref + ";' in attribute '" + attributeName + "'");
    }
  }
  return value;
}

void XmlPullParser::skipPast(std::string_view terminator, const char* what, int startLine,
                             std::size_t maxBytes) {
  std::size_t matched = 0;
  std::size_t seen = 0;
  while (matched < terminator.size()) {
    const int c = get();
    if (c < 0) {
      failAt(startLine, std::string("unterminated XML: ") + what + " is never closed with '" +
                            std::string(terminator) + "'");
    }
    if (++seen > maxBytes) {
      failAt(startLine,
             std::string(what) + " is longer than " + std::to_string(maxBytes) + " bytes");
    }
    if (c == terminator[matched]) {
      ++matched;
    } else if (matched == 2 && terminator == "-->" && c == '-') {
      // "--->": the last two dashes still start the terminator
    } else {
      matched = (c == terminator[0]) ? 1 : 0;
    }
  }
}

XmlEvent XmlPullParser::startElement(int line) {
  XmlEvent ev;
  ev.kind = XmlEvent::Kind::StartElement;
  ev.line = line;
  ev.name = readName("an element name");
  if (open_.empty() && sawRoot_) {
    failAt(line, "a second root element <" + ev.name + "> after the first one closed");
  }
  if (open_.size() >= kMaxDepth) {
    failAt(line, "elements nested deeper than " + std::to_string(kMaxDepth) + " levels");
  }
  while (true) {
    const bool spaced = isSpace(peek());
    skipSpace();
    const int c = peek();
    if (c < 0) {
      failAt(line, "unterminated XML: the file ends inside the tag <" + ev.name);
    }
    if (c == '>') {
      get();
      break;
    }
    if (c == '/') {
      get();
      expect('>', "after '/' in an empty-element tag");
      pendingEnd_ = true;
      pendingEndName_ = ev.name;
      break;
    }
    if (!spaced)
      fail("expected whitespace before attribute in <" + ev.name + ">, found " + shown(c));
    XmlAttribute a;
    a.name = readName("an attribute name");
    skipSpace();
    expect('=', ("after attribute name '" + a.name + "'").c_str());
    skipSpace();
    a.value = readAttributeValue(a.name);
    if (ev.attribute(a.name) != nullptr) {
      fail("attribute '" + a.name + "' appears twice in <" + ev.name + ">");
    }
    if (ev.attributes.size() >= kMaxAttributes) {
      fail("more than " + std::to_string(kMaxAttributes) + " attributes in <" + ev.name + ">");
    }
    ev.attributes.push_back(std::move(a));
  }
  sawRoot_ = true;
  if (!pendingEnd_) open_.push_back({ev.name, line});
  return ev;
}

XmlEvent XmlPullParser::endElement(int line) {
  XmlEvent ev;
  ev.kind = XmlEvent::Kind::EndElement;
  ev.line = line;
  ev.name = readName("an element name after '</'");
  skipSpace();
  expect('>', ("to close the tag </" + ev.name).c_str());
  if (open_.empty()) failAt(line, "closing tag </" + ev.name + "> without an open element");
  if (open_.back().name != ev.name) {
    failAt(line, "closing tag </" + ev.name + "> does not match <" + open_.back().name +
                     "> opened at line " + std::to_string(open_.back().line));
  }
  open_.pop_back();
  return ev;
}

XmlEvent XmlPullParser::next() {
  if (stopped_) fail("internal: the XML parser was used after the appended data");
  if (pendingEnd_) {
    pendingEnd_ = false;
    XmlEvent ev;
    ev.kind = XmlEvent::Kind::EndElement;
    ev.name = std::move(pendingEndName_);
    ev.line = line_;
    return ev;
  }
  while (true) {
    const int c = peek();
    if (c < 0) {
      if (!open_.empty()) {
        fail("unterminated XML: the file ends inside <" + open_.back().name + "> opened at line " +
             std::to_string(open_.back().line));
      }
      if (!sawRoot_) fail("not an XML file: it has no element");
      return XmlEvent{};
    }
    if (c != '<') {
      if (open_.empty()) {
        // Outside the root only whitespace may appear; fail at once on
        // anything else so a binary file is rejected at its first byte.
        if (!isSpace(c)) {
          fail(sawRoot_ ? "text " + shown(c) + " after the root element"
                        : "not an XML file: starts with " + shown(c) + ", expected '<'");
        }
        get();
        continue;
      }
      XmlEvent ev;
      ev.kind = XmlEvent::Kind::Text;
      ev.line = line_;
      ev.textBegin = offset_;
      while (true) {
        const int t = peek();
        if (t < 0 || t == '<') break;
        if (!isSpace(t)) ev.blank = false;
        get();
      }
      ev.textEnd = offset_;
      return ev;
    }
    const int line = line_;
    get();  // '<'
    const int k = peek();
    if (k == '?') {
      get();
      if (sawRoot_) failAt(line, "processing instruction after the root element's start");
      skipPast("?>", "the XML declaration or processing instruction", line, kMaxDeclarationBytes);
      continue;
    }
    if (k == '!') {
      get();
      if (peek() == '-') {
        get();
        expect('-', "to open a comment '<!--'");
        skipPast("-->", "a comment", line, SIZE_MAX);
        continue;
      }
      failAt(line, "'<!" + std::string(peek() == '[' ? "[CDATA[" : "DOCTYPE") +
                       "' is not supported in a VTK XML file");
    }
    if (k == '/') {
      get();
      return endElement(line);
    }
    return startElement(line);
  }
}

std::uint64_t XmlPullParser::offsetAfterMarker(char marker) {
  if (pendingEnd_) fail(std::string("expected content starting with '") + marker + "'");
  skipSpace();
  const int c = get();
  if (c != marker) {
    fail(std::string("expected '") + marker + "' before the appended data, found " + shown(c));
  }
  stopped_ = true;
  return offset_;
}

}  // namespace tessera::io_detail

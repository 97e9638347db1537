#pragma once
// A small, strict XML reader for the markup of VTK XML files: elements,
// attributes, comments and the XML declaration; no DTD, no CDATA, no
// namespace processing. It streams the file and never holds character data:
// text is reported as a byte range of the file, so an inline array of
// gigabytes costs nothing here. Limits on names, tags and nesting keep a
// hostile file from costing more than a few kilobytes.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "io/ByteStream.h"

namespace tessera::io_detail {

struct XmlAttribute {
  std::string name;
  std::string value;  // entities (&lt; &#65; ...) already replaced
};

struct XmlEvent {
  enum class Kind { StartElement, EndElement, Text, EndOfDocument };
  Kind kind = Kind::EndOfDocument;
  std::string name;                      // StartElement, EndElement
  std::vector<XmlAttribute> attributes;  // StartElement
  // Text: the file bytes [textBegin, textEnd), entities not replaced;
  // `blank` when they are all whitespace.
  std::uint64_t textBegin = 0;
  std::uint64_t textEnd = 0;
  bool blank = true;
  int line = 0;  // 1-based line where the event starts

  // The attribute's value, or nullptr when the element has none by that name.
  const std::string* attribute(std::string_view attributeName) const;
};

class XmlPullParser {
 public:
  // Errors are InputErrors that start with the file's name and the line.
  explicit XmlPullParser(const ByteSource& file);

  // The next event. An empty element <X/> gives StartElement then
  // EndElement. Text outside the root element must be whitespace and is not
  // reported. EndOfDocument once the root element is closed and only
  // whitespace, comments or processing instructions follow.
  XmlEvent next();

  // For an element whose content is not XML (VTK's raw <AppendedData>): skips
  // whitespace up to `marker` and returns the file offset just after it. The
  // parser cannot be used after this.
  std::uint64_t offsetAfterMarker(char marker);

  // Elements open around the current position.
  std::size_t depth() const { return open_.size(); }

 private:
  struct OpenElement {
    std::string name;
    int line;
  };

  int peek();
  int get();
  void expect(char c, const char* where);
  bool refill();
  void skipSpace();
  std::string readName(const char* what);
  std::string readAttributeValue(const std::string& attributeName);
  void skipPast(std::string_view terminator, const char* what, int startLine, std::size_t maxBytes);
  XmlEvent startElement(int line);
  XmlEvent endElement(int line);
  [[noreturn]] void fail(const std::string& msg) const;
  [[noreturn]] void failAt(int line, const std::string& msg) const;

  std::string what_;
  SourceStream file_;
  std::vector<unsigned char> buf_;
  std::size_t pos_ = 0;
  std::size_t len_ = 0;
  bool eof_ = false;
  std::uint64_t offset_ = 0;  // file offset of buf_[pos_]
  int line_ = 1;
  std::vector<OpenElement> open_;
  bool sawRoot_ = false;
  bool pendingEnd_ = false;  // an empty element <X/> still owes its EndElement
  std::string pendingEndName_;
  bool stopped_ = false;
};

}  // namespace tessera::io_detail

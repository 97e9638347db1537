#pragma once
// Text helpers shared by the readers of text headers (NRRD, MetaImage, VTK
// XML attributes, PVM, DICOM fields): trimming, splitting into words, and
// reading a header line by line from a ByteSource with a bound on its size.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/ByteStream.h"

namespace tessera::io_detail {

// `s` without leading and trailing blanks (space, tab, CR, LF).
std::string trim(std::string_view s);
// The words of `s`, split at blanks.
std::vector<std::string> words(std::string_view s);
// ASCII lower case.
std::string lower(std::string_view s);
// InputError "<file>: <format> header has no '<key>' field" unless `present`.
void requireField(bool present, const std::string& file, const char* format, const char* key);
// `v` as printf's "%g" writes it (six significant digits), for messages.
std::string numberString(double v);
// At most `max` characters of `s`, non-printable ones shown as '?'.
std::string printable(std::string_view s, std::size_t max);

// Lines of a header from the start of a source, without their CR LF / LF.
class LineReader {
 public:
  // A line longer than `maxLine` bytes is an InputError: "<name>: header
  // line longer than N bytes" followed by `hint`.
  LineReader(const ByteSource& source, std::size_t maxLine, std::string hint);
  // The next line; false at the end of the data when nothing was read.
  bool next(std::string& line);
  // Bytes read so far, newlines included: the offset of the next line.
  std::uint64_t consumed() const { return consumed_; }

 private:
  const ByteSource& source_;
  SourceStream in_;
  std::size_t maxLine_;
  std::string hint_;
  std::vector<char> buf_;
  std::size_t pos_ = 0;
  std::size_t len_ = 0;
  std::uint64_t consumed_ = 0;
};

}  // namespace tessera::io_detail

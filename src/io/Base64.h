#pragma once
// Base64 (RFC 4648 §4) decoded on the fly, for the binary arrays VTK XML
// files keep inline or in base64 <AppendedData>: nothing is held but a small
// buffer of text, so a huge array costs no more than its voxels.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "io/ByteStream.h"

namespace tessera::io_detail {

// The most bytes `chars` characters of base64 text can decode to (whitespace
// and padding only make it less).
constexpr std::uint64_t base64DecodedBound(std::uint64_t chars) {
  return chars / 4 * 3 + (chars % 4) * 3 / 4;
}

// The bytes that the base64 text read from `text` decodes to. Whitespace is
// skipped. A run may end in '=' padding with another run after it: VTK
// encodes a compressed array's header and its blocks as separate runs. The
// text ends after `maxChars` characters, at the end of `text`, or at a '<'
// (the tag after the text). Any other character that is not base64 is an
// InputError naming `what` and the character's file offset (`firstOffset` is
// the offset of the first character).
class Base64Stream : public ByteStream {
 public:
  Base64Stream(ByteStream& text, std::uint64_t maxChars, std::string what,
               std::uint64_t firstOffset);
  std::size_t read(std::byte* dst, std::size_t n) override;

 private:
  // Next character that is not whitespace, or -1 at the end of the text.
  int nextSymbol();
  // Decodes the next group of four characters into pending_; false at the end.
  bool decodeGroup();
  [[noreturn]] void fail(const std::string& msg, std::uint64_t offset) const;

  ByteStream& text_;
  std::uint64_t charsLeft_;
  std::string what_;
  std::uint64_t offset_;  // file offset of the next character in buf_
  std::vector<unsigned char> buf_;
  std::size_t pos_ = 0;
  std::size_t len_ = 0;
  bool ended_ = false;
  unsigned char pending_[3] = {0, 0, 0};
  int pendingPos_ = 0;
  int pendingLen_ = 0;
};

}  // namespace tessera::io_detail

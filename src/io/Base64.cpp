#include "io/Base64.h"

#include <algorithm>
#include <array>
#include <cstdio>

#include "tessera/core/Error.h"

namespace tessera::io_detail {

namespace {

constexpr std::size_t kTextChunk = 64 * 1024;
constexpr int kInvalid = -1;
constexpr int kPad = -2;

constexpr std::array<int, 256> makeTable() {
  std::array<int, 256> t{};
  for (int& v : t) v = kInvalid;
  const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  for (int i = 0; i < 64; ++i) t[static_cast<unsigned char>(alphabet[i])] = i;
  t[static_cast<unsigned char>('=')] = kPad;
  return t;
}
constexpr std::array<int, 256> kTable = makeTable();

bool isXmlSpace(int c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

std::string shownChar(int c) {
  if (c >= 0x21 && c < 0x7f) return std::string("'") + static_cast<char>(c) + "'";
  char buf[16];
  std::snprintf(buf, sizeof buf, "byte 0x%02x", static_cast<unsigned>(c));
  return buf;
}

}  // namespace

Base64Stream::Base64Stream(ByteStream& text, std::uint64_t maxChars, std::string what,
                           std::uint64_t firstOffset)
    : text_(text),
      charsLeft_(maxChars),
      what_(std::move(what)),
      offset_(firstOffset),
      buf_(kTextChunk) {}

void Base64Stream::fail(const std::string& msg, std::uint64_t offset) const {
  throw InputError(what_ + ": base64 data at byte " + std::to_string(offset) + ": " + msg);
}

int Base64Stream::nextSymbol() {
  while (true) {
    if (pos_ == len_) {
      if (ended_ || charsLeft_ == 0) {
        ended_ = true;
        return -1;
      }
      const std::size_t want =
          static_cast<std::size_t>(std::min<std::uint64_t>(buf_.size(), charsLeft_));
      len_ = text_.read(reinterpret_cast<std::byte*>(buf_.data()), want);
      pos_ = 0;
      charsLeft_ -= len_;
      if (len_ == 0) {
        ended_ = true;
        return -1;
      }
    }
    const int c = buf_[pos_];
    if (c == '<') {  // the next XML tag ends the text
      ended_ = true;
      pos_ = len_ = 0;
      return -1;
    }
    ++pos_;
    ++offset_;
    if (!isXmlSpace(c)) return c;
  }
}

bool Base64Stream::decodeGroup() {
  int sextets[4] = {0, 0, 0, 0};
  int n = 0;    // characters in this group
  int pad = 0;  // '=' among them
  while (n < 4) {
    const int c = nextSymbol();
    if (c < 0) {
      if (n == 0) return false;
      if (pad > 0 || n == 1) {
        fail("the text ends inside a group of 4 characters", offset_);
      }
      break;  // unpadded tail of 2 or 3 characters: what it holds is clear
    }
    const int v = kTable[static_cast<unsigned char>(c)];
    if (v == kInvalid) {
      fail(shownChar(c) + " is not a base64 character", offset_ - 1);
    }
    if (v == kPad) {
      if (n < 2) fail("'=' padding where data must be", offset_ - 1);
      ++pad;
      sextets[n++] = 0;
      continue;
    }
    if (pad > 0) fail("data after '=' padding inside a group of 4", offset_ - 1);
    sextets[n++] = v;
  }
  const std::uint32_t bits = (static_cast<std::uint32_t>(sextets[0]) << 18) |
                             (static_cast<std::uint32_t>(sextets[1]) << 12) |
                             (static_cast<std::uint32_t>(sextets[2]) << 6) |
                             static_cast<std::uint32_t>(sextets[3]);
  pending_[0] = static_cast<unsigned char>(bits >> 16);
  pending_[1] = static_cast<unsigned char>(bits >> 8);
  pending_[2] = static_cast<unsigned char>(bits);
  pendingLen_ = n - 1 - pad;  // 4 characters hold 3 bytes, 3 hold 2, 2 hold 1
  pendingPos_ = 0;
  return true;
}

std::size_t Base64Stream::read(std::byte* dst, std::size_t n) {
  std::size_t done = 0;
  while (done < n) {
    if (pendingPos_ == pendingLen_) {
      // Fast path: whole groups of plain characters straight from the buffer.
      while (n - done >= 3 && len_ - pos_ >= 4) {
        const int a = kTable[buf_[pos_]];
        const int b = kTable[buf_[pos_ + 1]];
        const int c = kTable[buf_[pos_ + 2]];
        const int d = kTable[buf_[pos_ + 3]];
        if ((a | b | c | d) < 0) break;  // padding, whitespace or junk: the slow path
        const std::uint32_t bits =
            (static_cast<std::uint32_t>(a) << 18) | (static_cast<std::uint32_t>(b) << 12) |
            (static_cast<std::uint32_t>(c) << 6) | static_cast<std::uint32_t>(d);
        dst[done] = static_cast<std::byte>(bits >> 16);
        dst[done + 1] = static_cast<std::byte>(bits >> 8);
        dst[done + 2] = static_cast<std::byte>(bits);
        done += 3;
        pos_ += 4;
        offset_ += 4;
      }
      if (done == n) break;
      if (!decodeGroup()) break;
      continue;
    }
    dst[done++] = static_cast<std::byte>(pending_[pendingPos_++]);
  }
  return done;
}

}  // namespace tessera::io_detail

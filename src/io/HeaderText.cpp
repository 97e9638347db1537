#include "io/HeaderText.h"

#include <algorithm>
#include <cctype>
#include <cstdio>

#include "tessera/core/Error.h"

namespace tessera::io_detail {

namespace {
bool blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}
}  // namespace

std::string trim(std::string_view s) {
  std::size_t b = 0;
  std::size_t e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r' || s[b] == '\n')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r' || s[e - 1] == '\n'))
    --e;
  return std::string(s.substr(b, e - b));
}

std::vector<std::string> words(std::string_view s) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && blank(s[i])) ++i;
    const std::size_t b = i;
    while (i < s.size() && !blank(s[i])) ++i;
    if (i > b) out.emplace_back(s.substr(b, i - b));
  }
  return out;
}

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

void requireField(bool present, const std::string& file, const char* format, const char* key) {
  if (!present) {
    throw InputError(file + ": " + format + " header has no '" + std::string(key) + "' field");
  }
}

std::string numberString(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string printable(std::string_view s, std::size_t max) {
  std::string out;
  for (char c : s.substr(0, max)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return out;
}

LineReader::LineReader(const ByteSource& source, std::size_t maxLine, std::string hint)
    : source_(source), in_(source, 0), maxLine_(maxLine), hint_(std::move(hint)), buf_(64 * 1024) {}

bool LineReader::next(std::string& line) {
  line.clear();
  bool any = false;
  while (true) {
    if (pos_ == len_) {
      len_ = in_.read(reinterpret_cast<std::byte*>(buf_.data()), buf_.size());
      pos_ = 0;
      if (len_ == 0) break;
    }
    const char c = buf_[pos_++];
    any = true;
    ++consumed_;
    if (c == '\n') break;
    if (line.size() >= maxLine_) {
      throw InputError(source_.name() + ": header line longer than " + std::to_string(maxLine_) +
                       " bytes" + hint_);
    }
    line += c;
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return any;
}

}  // namespace tessera::io_detail

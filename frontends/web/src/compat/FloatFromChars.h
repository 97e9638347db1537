#pragma once
// Emscripten 3.1.6's libc++ has no floating-point std::from_chars, which the
// io readers use to read numbers in the C locale. Force-included into
// src/io/*.cpp by cmake/Web.cmake only. Same contract as the standard's
// general format: no leading blank or '+', the longest decimal prefix
// (a hex "0x" stops after the 0), inf/nan, result_out_of_range (value
// untouched) on overflow or underflow.
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <string>
#include <system_error>

namespace tessera::web_compat {
template <class T, class Parse>
std::from_chars_result fromChars(const char* first, const char* last, T& value, Parse parse) {
  if (first == last || *first == '+' || std::isspace(static_cast<unsigned char>(*first))) {
    return {first, std::errc::invalid_argument};
  }
  std::string text(first, last);  // strtod needs a terminator
  const std::size_t x = text.find_first_of("xX");
  if (x != std::string::npos) text.resize(x);
  errno = 0;
  char* end = nullptr;
  const T v = parse(text.c_str(), &end);
  if (end == text.c_str()) return {first, std::errc::invalid_argument};
  const char* ptr = first + (end - text.c_str());
  if (errno == ERANGE) return {ptr, std::errc::result_out_of_range};
  value = v;
  return {ptr, std::errc{}};
}
}  // namespace tessera::web_compat

namespace std {  // NOLINT: supplies the overloads the standard promises
inline from_chars_result from_chars(const char* first, const char* last, double& value) {
  return tessera::web_compat::fromChars(first, last, value,
                                        [](const char* s, char** e) { return std::strtod(s, e); });
}
inline from_chars_result from_chars(const char* first, const char* last, float& value) {
  return tessera::web_compat::fromChars(first, last, value,
                                        [](const char* s, char** e) { return std::strtof(s, e); });
}
}  // namespace std

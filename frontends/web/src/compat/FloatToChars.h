#pragma once
// Emscripten 3.1.6's libc++ has no floating-point std::to_chars, which
// core/TransferFunction.cpp uses for the shortest round-trip text of a
// number. Force-included into that file by cmake/Web.cmake only. Same
// contract: the shortest "%.Ng" text that reads back as exactly `v`.
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <system_error>

namespace std {  // NOLINT: supplies the overload the standard promises
inline to_chars_result to_chars(char* first, char* last, double v) {
  char buf[40];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v || precision == 17) break;
  }
  const std::size_t n = std::strlen(buf);
  if (n > static_cast<std::size_t>(last - first)) return {last, std::errc::value_too_large};
  std::memcpy(first, buf, n);
  return {first + n, std::errc{}};
}
}  // namespace std

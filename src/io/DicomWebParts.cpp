#include "io/DicomWebParts.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "tessera/core/Error.h"

namespace tessera::io_detail {

namespace {

std::string lowered(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// The `;`-separated pieces of a header value, quotes respected.
std::vector<std::string_view> headerPieces(std::string_view v) {
  std::vector<std::string_view> out;
  bool quoted = false;
  std::size_t start = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (v[i] == '"') quoted = !quoted;
    if (v[i] == ';' && !quoted) {
      out.push_back(trim(v.substr(start, i - start)));
      start = i + 1;
    }
  }
  out.push_back(trim(v.substr(start)));
  return out;
}

std::string_view asText(std::span<const std::byte> bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

// A short printable excerpt of what was received, for messages.
std::string excerpt(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, 40)) {
    const auto u = static_cast<unsigned char>(c);
    out += (u >= 0x20 && u < 0x7f) ? c : '.';
  }
  return "'" + out + (s.size() > 40 ? "...'" : "'");
}

}  // namespace

std::optional<std::string> mediaParameter(std::string_view contentType, std::string_view name) {
  const std::vector<std::string_view> pieces = headerPieces(contentType);
  for (std::size_t i = 1; i < pieces.size(); ++i) {
    const std::size_t eq = pieces[i].find('=');
    if (eq == std::string_view::npos) continue;
    if (lowered(trim(pieces[i].substr(0, eq))) != lowered(name)) continue;
    std::string_view value = trim(pieces[i].substr(eq + 1));
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"') {
      value = value.substr(1, value.size() - 2);
    }
    return std::string(value);
  }
  return std::nullopt;
}

std::string mediaType(std::string_view contentType) {
  return lowered(headerPieces(contentType).front());
}

std::vector<MultipartPart> parseMultipart(std::string_view contentType,
                                          std::span<const std::byte> body, const std::string& what,
                                          std::size_t maxParts) {
  auto fail = [&](const std::string& why) -> InputError {
    return InputError(what + ": multipart body: " + why);
  };
  if (mediaType(contentType).rfind("multipart/", 0) != 0) {
    throw fail("Content-Type is '" + std::string(contentType.substr(0, 80)) +
               "', expected multipart/related");
  }
  const std::optional<std::string> boundary = mediaParameter(contentType, "boundary");
  // RFC 2046 5.1.1: 1 to 70 characters.
  if (!boundary || boundary->empty() || boundary->size() > 70) {
    throw fail("Content-Type '" + std::string(contentType.substr(0, 120)) +
               "' has no valid boundary parameter");
  }
  const std::string_view text = asText(body);
  const std::string dash = "--" + *boundary;
  const std::string delimiter = "\r\n" + dash;
  // The first delimiter may open the body or follow a preamble.
  std::size_t at = 0;
  if (text.compare(0, dash.size(), dash) != 0) {
    at = text.find(delimiter);
    if (at == std::string_view::npos) {
      throw fail("the boundary '" + *boundary + "' of its Content-Type never occurs (body starts " +
                 excerpt(text) + ")");
    }
    at += 2;
  }
  std::vector<MultipartPart> parts;
  for (;;) {
    at += dash.size();
    if (text.compare(at, 2, "--") == 0) break;  // the close delimiter
    // Transport padding, then CRLF.
    while (at < text.size() && (text[at] == ' ' || text[at] == '\t')) ++at;
    if (text.compare(at, 2, "\r\n") != 0) {
      throw fail(at >= text.size()
                     ? "ends after a boundary, without the close delimiter '" + dash + "--'"
                     : "a boundary is not followed by a line break");
    }
    at += 2;
    const std::size_t headersEnd = text.find("\r\n\r\n", at - 2);
    if (headersEnd == std::string_view::npos) {
      throw fail("part " + std::to_string(parts.size() + 1) + "'s headers never end");
    }
    MultipartPart part;
    std::optional<std::uint64_t> declared;
    std::size_t line = at;
    while (line < headersEnd + 2) {
      const std::size_t end = text.find("\r\n", line);
      const std::string_view header = text.substr(line, end - line);
      line = end + 2;
      const std::size_t colon = header.find(':');
      if (colon == std::string_view::npos) continue;
      const std::string name = lowered(trim(header.substr(0, colon)));
      const std::string_view value = trim(header.substr(colon + 1));
      if (name == "content-type") part.contentType = std::string(value);
      if (name == "content-length") {
        std::uint64_t n = 0;
        const auto r = std::from_chars(value.data(), value.data() + value.size(), n);
        if (r.ec != std::errc() || r.ptr != value.data() + value.size()) {
          throw fail("part " + std::to_string(parts.size() + 1) + " has Content-Length '" +
                     std::string(value.substr(0, 40)) + "'");
        }
        declared = n;
      }
    }
    const std::size_t start = headersEnd + 4;
    const std::size_t next = text.find(delimiter, start);
    if (next == std::string_view::npos) {
      throw fail("part " + std::to_string(parts.size() + 1) +
                 " never ends: no boundary after it (truncated?)");
    }
    if (declared && *declared != next - start) {
      throw fail("part " + std::to_string(parts.size() + 1) + " declares Content-Length " +
                 std::to_string(*declared) + " but holds " + std::to_string(next - start) +
                 " bytes");
    }
    if (parts.size() == maxParts) {
      throw fail("more than the " + std::to_string(maxParts) + " parts expected");
    }
    part.body = body.subspan(start, next - start);
    parts.push_back(std::move(part));
    at = next + 2;
  }
  if (parts.empty()) throw fail("no part");
  return parts;
}

std::string frameTransferSyntax(std::string_view partContentType) {
  if (auto ts = mediaParameter(partContentType, "transfer-syntax")) return *ts;
  const std::string type = mediaType(partContentType);
  // PS3.18 table 8.7.3-5: each media type's default transfer syntax.
  if (type == "application/octet-stream") return "1.2.840.10008.1.2.1";
  if (type == "image/jpeg") return "1.2.840.10008.1.2.4.70";
  if (type == "image/jls") return "1.2.840.10008.1.2.4.80";
  if (type == "image/jp2") return "1.2.840.10008.1.2.4.90";
  if (type == "image/jpx") return "1.2.840.10008.1.2.4.92";
  if (type == "image/jphc") return "1.2.840.10008.1.2.4.201";
  if (type == "image/x-dicom-rle" || type == "image/dicom-rle") return "1.2.840.10008.1.2.5";
  return "";
}

nlohmann::json parseDicomJson(std::span<const std::byte> body, const std::string& what) {
  const std::string_view text = asText(body);
  // nlohmann's parser keeps its own stack, but a value nested thousands deep
  // is no DICOM JSON: refused before anything is built.
  int depth = 0;
  bool inString = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (inString) {
      if (c == '\\') ++i;
      if (c == '"') inString = false;
      continue;
    }
    if (c == '"') inString = true;
    if (c == '[' || c == '{') {
      if (++depth > kMaxJsonNesting) {
        throw InputError(what + ": JSON nested deeper than " + std::to_string(kMaxJsonNesting) +
                         " levels; not DICOM JSON");
      }
    }
    if (c == ']' || c == '}') --depth;
  }
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(what + ": not JSON (" + std::to_string(text.size()) + " bytes starting " +
                     excerpt(text) + "; parse error at byte " + std::to_string(e.byte) + ")");
  } catch (const nlohmann::json::out_of_range&) {
    // A number no double holds (1e999): found by fuzz_functional_groups.
    throw InputError(what + ": not DICOM JSON (" + std::to_string(text.size()) +
                     " bytes starting " + excerpt(text) + "): a number too large for a double");
  }
  if (!j.is_array()) {
    throw InputError(what + ": JSON " + std::string(j.type_name()) +
                     ", expected an array of DICOM JSON datasets");
  }
  for (std::size_t i = 0; i < j.size(); ++i) {
    if (!j[i].is_object()) {
      throw InputError(what + ": JSON array item " + std::to_string(i) + " is " +
                       std::string(j[i].type_name()) + ", expected a DICOM JSON dataset (object)");
    }
  }
  return j;
}

const nlohmann::json* DicomJsonAttributes::element(DicomTag tag) const {
  char key[9];
  std::snprintf(key, sizeof key, "%04X%04X", tag.group, tag.element);
  auto it = dataset_.find(key);
  if (it == dataset_.end()) {
    std::snprintf(key, sizeof key, "%04x%04x", tag.group, tag.element);
    it = dataset_.find(key);
  }
  if (it == dataset_.end() || !it->is_object()) return nullptr;
  return &*it;
}

bool DicomJsonAttributes::has(DicomTag tag) const {
  return element(tag) != nullptr;
}

std::optional<std::string> DicomJsonAttributes::text(DicomTag tag) const {
  constexpr std::size_t kLongestAttribute = 64 * 1024;
  const nlohmann::json* e = element(tag);
  if (e == nullptr) return std::nullopt;
  const auto values = e->find("Value");
  if (values == e->end()) return std::string();
  if (!values->is_array()) return std::nullopt;
  std::string out;
  for (std::size_t i = 0; i < values->size(); ++i) {
    const nlohmann::json& v = (*values)[i];
    if (i > 0) out += '\\';
    if (v.is_string()) {
      out += v.get_ref<const std::string&>();
    } else if (v.is_number_integer()) {
      out += v.is_number_unsigned() ? std::to_string(v.get<std::uint64_t>())
                                    : std::to_string(v.get<std::int64_t>());
    } else if (v.is_number_float()) {
      // The shortest text that reads back to the same double (to_chars),
      // so that a DS sent as a JSON number gives the folder reader's value.
      char buf[32];
      const auto r = std::to_chars(buf, buf + sizeof buf, v.get<double>());
      out.append(buf, r.ptr);
    } else if (v.is_object()) {
      const auto a = v.find("Alphabetic");
      if (a != v.end() && a->is_string()) out += a->get_ref<const std::string&>();
    } else if (!v.is_null()) {
      return std::nullopt;  // a sequence or something else no text holds
    }
    if (out.size() > kLongestAttribute) return std::nullopt;
  }
  const auto b = out.find_first_not_of(std::string(" \0", 2));
  const auto end = out.find_last_not_of(std::string(" \0", 2));
  return b == std::string::npos ? std::string() : out.substr(b, end - b + 1);
}

std::optional<int> DicomJsonAttributes::uint16(DicomTag tag) const {
  const nlohmann::json* e = element(tag);
  if (e == nullptr) return std::nullopt;
  const auto values = e->find("Value");
  if (values == e->end() || !values->is_array() || values->empty()) return std::nullopt;
  const nlohmann::json& v = values->front();
  if (v.is_number_integer()) {
    const std::int64_t n = v.get<std::int64_t>();
    if (n >= 0 && n <= 65535) return static_cast<int>(n);
    return std::nullopt;
  }
  if (v.is_string()) {
    const std::string& s = v.get_ref<const std::string&>();
    int n = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), n);
    if (r.ec == std::errc() && r.ptr == s.data() + s.size() && n >= 0 && n <= 65535) return n;
  }
  return std::nullopt;
}

// A sequence's items (PS3.18 F.2.5: "Value" holds one object per item);
// the items point into the answer, which outlives them while the series'
// headers are read. Nesting is bounded before parsing (kMaxJsonNesting).
std::vector<std::unique_ptr<DicomAttributes>> DicomJsonAttributes::items(DicomTag tag) const {
  std::vector<std::unique_ptr<DicomAttributes>> out;
  const nlohmann::json* e = element(tag);
  if (e == nullptr) return out;
  const auto vr = e->find("vr");
  if (vr != e->end() && !(vr->is_string() && vr->get_ref<const std::string&>() == "SQ")) return out;
  const auto values = e->find("Value");
  if (values == e->end() || !values->is_array()) return out;
  for (const nlohmann::json& item : *values) {
    if (item.is_object()) out.push_back(std::make_unique<DicomJsonAttributes>(item));
  }
  return out;
}

}  // namespace tessera::io_detail

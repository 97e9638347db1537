#include "tessera/io/ZarrArray.h"

#include <blosc.h>
#include <zlib.h>
#include <zstd.h>

#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera {

namespace {

using nlohmann::json;

// Zarr's dtype strings ("<u2", "|u1", ">f8"); structured, string, complex
// and datetime dtypes are refused.
void parseDtype(const json& j, const std::string& name, ZarrArrayMeta& m) {
  if (!j.is_string()) throw InputError(name + ": dtype must be a string such as \"<u2\"");
  const std::string d = j.get<std::string>();
  m.dtype = d;
  if (d.size() < 3 || (d[0] != '<' && d[0] != '>' && d[0] != '|')) {
    throw InputError(name + ": dtype \"" + d + "\" is not <TYPE, >TYPE or |TYPE");
  }
  m.kind = d[1];
  const std::string size = d.substr(2);
  m.itemSize = size == "1" ? 1 : size == "2" ? 2 : size == "4" ? 4 : size == "8" ? 8 : 0;
  const bool known = (m.kind == 'b' && m.itemSize == 1) ||
                     ((m.kind == 'i' || m.kind == 'u') && m.itemSize > 0) ||
                     (m.kind == 'f' && (m.itemSize == 4 || m.itemSize == 8));
  if (!known) {
    throw InputError(name + ": dtype \"" + d +
                     "\" is not supported (bool, signed/unsigned integers of 1-8 bytes, f4, f8)");
  }
  m.bigEndian = d[0] == '>' && m.itemSize > 1;
  if (m.kind == 'u' && m.itemSize == 1) {
    m.target = ScalarType::U8;
  } else if (m.kind == 'u' && m.itemSize == 2) {
    m.target = ScalarType::U16;
  } else if (m.kind == 'i' && m.itemSize == 2) {
    m.target = ScalarType::I16;
  } else if (m.kind == 'f' && m.itemSize == 4) {
    m.target = ScalarType::F32;
  } else {
    m.target = ScalarType::F32;
    m.converted = true;
  }
}

std::vector<std::int64_t> positiveList(const json& doc, const char* key, const std::string& name) {
  if (!doc.contains(key) || !doc[key].is_array()) {
    throw InputError(name + ": \"" + key + "\" must be a list of integers");
  }
  std::vector<std::int64_t> out;
  for (const json& v : doc[key]) {
    if (!v.is_number_integer() || v.get<std::int64_t>() <= 0 ||
        v.get<std::int64_t>() > (std::int64_t{1} << 40)) {
      throw InputError(name + ": " + key + " " + doc[key].dump() +
                       " holds a value that is not a positive integer (up to 2^40)");
    }
    out.push_back(v.get<std::int64_t>());
  }
  return out;
}

double parseFill(const json& f, const std::string& name) {
  if (f.is_null()) return 0.0;
  if (f.is_boolean()) return f.get<bool>() ? 1.0 : 0.0;
  if (f.is_number()) return f.get<double>();
  if (f.is_string()) {
    const std::string s = f.get<std::string>();
    if (s == "NaN") return std::numeric_limits<double>::quiet_NaN();
    if (s == "Infinity") return std::numeric_limits<double>::infinity();
    if (s == "-Infinity") return -std::numeric_limits<double>::infinity();
  }
  throw InputError(name + ": fill_value " + f.dump() +
                   " is not a number, null, \"NaN\", \"Infinity\" or \"-Infinity\"");
}

void parseCompressor(const json& c, const std::string& name, ZarrArrayMeta& m) {
  if (c.is_null()) {
    m.compressor = ZarrCompressor::None;
    m.compressorText = "none";
    return;
  }
  if (!c.is_object() || !c.contains("id") || !c["id"].is_string()) {
    throw InputError(name + ": compressor " + c.dump() + " has no \"id\"");
  }
  const std::string id = c["id"].get<std::string>();
  m.compressorText = id;
  if (id == "zlib") {
    m.compressor = ZarrCompressor::Zlib;
  } else if (id == "gzip") {
    m.compressor = ZarrCompressor::Gzip;
  } else if (id == "zstd") {
    m.compressor = ZarrCompressor::Zstd;
  } else if (id == "blosc") {
    m.compressor = ZarrCompressor::Blosc;
    // The inner codec and shuffle are in each chunk's blosc header; these
    // are for `info` only.
    const std::string cname = c.value("cname", std::string("?"));
    const int shuffle =
        c.contains("shuffle") && c["shuffle"].is_number_integer() ? c["shuffle"].get<int>() : 1;
    m.compressorText += " " + cname +
                        (shuffle == 2   ? " bitshuffle"
                         : shuffle == 1 ? " shuffle"
                                        : " noshuffle");
  } else {
    throw InputError(name + ": compressor \"" + id +
                     "\" is not supported (zlib, gzip, zstd, blosc or null)");
  }
}

}  // namespace

ZarrCompressor parseZarrCompressor(const std::string& name) {
  if (name == "none") return ZarrCompressor::None;
  if (name == "zlib") return ZarrCompressor::Zlib;
  if (name == "gzip") return ZarrCompressor::Gzip;
  if (name == "zstd") return ZarrCompressor::Zstd;
  if (name == "blosc") return ZarrCompressor::Blosc;
  throw InputError("compressor '" + name + "': expected zstd, blosc, zlib, gzip or none");
}

std::uint64_t ZarrArrayMeta::chunkElements() const {
  std::uint64_t n = 1;
  for (std::int64_t c : chunks) n *= std::uint64_t(c);
  return n;
}

std::uint64_t ZarrArrayMeta::maxStoredChunkBytes() const {
  // Worst expansion on incompressible data: zlib/gzip ~0.03% + 18 B
  // (deflateBound), zstd ~0.4% + 64 B + checksum (ZSTD_compressBound),
  // blosc 16 B header + 4 B per block. 1/64 + 1 KiB covers every one.
  const std::uint64_t raw = chunkBytes();
  return raw + raw / 64 + 1024;
}

std::string ZarrArrayMeta::chunkKey(std::span<const std::int64_t> index) const {
  std::string key;
  for (std::size_t i = 0; i < index.size(); ++i) {
    if (i) key += separator;
    key += std::to_string(index[i]);
  }
  return key;
}

namespace {
ZarrArrayMeta parseZarrayFields(std::string_view text, const std::string& name);
}  // namespace

// A field of the wrong JSON type ("order": 0) is a bad file, not a crash:
// nlohmann's type errors become an InputError naming the .zarray.
ZarrArrayMeta parseZarray(std::string_view text, const std::string& name) {
  try {
    return parseZarrayFields(text, name);
  } catch (const json::exception& e) {
    throw InputError(name + ": a field has the wrong type or value (" + e.what() + ")");
  }
}

namespace {
ZarrArrayMeta parseZarrayFields(std::string_view text, const std::string& name) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(name + ": not valid JSON (" + e.what() + ")");
  }
  if (!doc.is_object()) throw InputError(name + ": not a JSON object");
  if (!doc.contains("zarr_format") || doc["zarr_format"] != 2) {
    throw InputError(name + ": zarr_format is " +
                     (doc.contains("zarr_format") ? doc["zarr_format"].dump() : "missing") +
                     ", expected 2 (Zarr v2)");
  }
  ZarrArrayMeta m;
  m.shape = positiveList(doc, "shape", name);
  m.chunks = positiveList(doc, "chunks", name);
  if (m.shape.size() != m.chunks.size() || m.shape.empty() || m.shape.size() > 5) {
    throw InputError(name + ": shape has " + std::to_string(m.shape.size()) + " axes, chunks " +
                     std::to_string(m.chunks.size()) + " (expected the same number, 1 to 5)");
  }
  if (!doc.contains("dtype")) throw InputError(name + ": no dtype");
  parseDtype(doc["dtype"], name, m);
  const std::string order = doc.value("order", std::string("C"));
  if (order != "C") {
    throw InputError(name + ": order \"" + order +
                     "\" (Fortran) is not supported; rewrite the array with order \"C\"");
  }
  m.fill = parseFill(doc.contains("fill_value") ? doc["fill_value"] : json(), name);
  if (doc.contains("dimension_separator") && !doc["dimension_separator"].is_null()) {
    const json& s = doc["dimension_separator"];
    if (!s.is_string() || (s != "." && s != "/")) {
      throw InputError(name + ": dimension_separator " + s.dump() + " is neither \".\" nor \"/\"");
    }
    m.separator = s.get<std::string>()[0];
  }
  if (doc.contains("filters") && !doc["filters"].is_null() &&
      !(doc["filters"].is_array() && doc["filters"].empty())) {
    throw InputError(name + ": filters " + doc["filters"].dump() + " are not supported");
  }
  parseCompressor(doc.contains("compressor") ? doc["compressor"] : json(), name, m);
  // Saturating products: 2^40 per axis overflows 64 bits over five axes.
  long double elements = 1.0L;
  for (std::int64_t c : m.chunks) elements *= static_cast<long double>(c);
  if (elements * m.itemSize > 1.0e15L) {
    throw BudgetError(name + ": chunks " + doc["chunks"].dump() + " of " + m.dtype +
                      " are larger than any host can hold");
  }
  HostBudget::global().check(m.chunkBytes(), name + ": one chunk " + doc["chunks"].dump());
  return m;
}
}  // namespace

std::string zarrayJson(const std::vector<std::int64_t>& shape,
                       const std::vector<std::int64_t>& chunks, ScalarType type,
                       ZarrCompressor compressor) {
  json doc;
  doc["zarr_format"] = 2;
  doc["shape"] = shape;
  doc["chunks"] = chunks;
  doc["dtype"] = type == ScalarType::U8    ? "|u1"
                 : type == ScalarType::U16 ? "<u2"
                 : type == ScalarType::I16 ? "<i2"
                                           : "<f4";
  doc["order"] = "C";
  doc["fill_value"] = 0;
  doc["filters"] = nullptr;
  doc["dimension_separator"] = "/";
  switch (compressor) {
    case ZarrCompressor::None:
      doc["compressor"] = nullptr;
      break;
    case ZarrCompressor::Zlib:
      doc["compressor"] = {{"id", "zlib"}, {"level", 6}};
      break;
    case ZarrCompressor::Gzip:
      doc["compressor"] = {{"id", "gzip"}, {"level", 6}};
      break;
    case ZarrCompressor::Zstd:
      doc["compressor"] = {{"id", "zstd"}, {"level", 3}};
      break;
    case ZarrCompressor::Blosc:
      doc["compressor"] = {
          {"id", "blosc"}, {"cname", "lz4"}, {"clevel", 5}, {"shuffle", 1}, {"blocksize", 0}};
      break;
  }
  return doc.dump(2);
}

namespace {

std::vector<std::byte> inflateChunk(std::span<const std::byte> in, std::uint64_t expected,
                                    bool gzip, const std::string& where) {
  std::vector<std::byte> out(expected);
  z_stream zs{};
  if (inflateInit2(&zs, gzip ? 15 + 16 : 15) != Z_OK) {
    throw Error(where + ": zlib inflateInit failed");
  }
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(in.data()));
  zs.avail_in = static_cast<uInt>(in.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  const int ret = inflate(&zs, Z_FINISH);
  const std::uint64_t produced = zs.total_out;
  const char* msg = zs.msg;
  const std::string reason = msg ? msg : "";
  inflateEnd(&zs);
  const char* codec = gzip ? "gzip" : "zlib";
  if (ret == Z_STREAM_END && produced == expected) return out;
  if (ret == Z_STREAM_END) {
    throw InputError(where + ": " + codec + " chunk decompressed to " + std::to_string(produced) +
                     " bytes, expected " + std::to_string(expected));
  }
  if (ret == Z_BUF_ERROR && zs.avail_out == 0) {
    throw InputError(where + ": " + codec + " chunk decompresses to more than the expected " +
                     std::to_string(expected) + " bytes");
  }
  if (ret == Z_BUF_ERROR) {
    throw InputError(where + ": truncated " + codec + " chunk (" + std::to_string(in.size()) +
                     " bytes stored, stream ends after " + std::to_string(produced) + " of " +
                     std::to_string(expected) + " bytes)");
  }
  throw InputError(where + ": corrupt " + codec + " chunk" + (reason.empty() ? "" : ": " + reason));
}

std::vector<std::byte> zstdChunk(std::span<const std::byte> in, std::uint64_t expected,
                                 const std::string& where) {
  const unsigned long long declared = ZSTD_getFrameContentSize(in.data(), in.size());
  if (declared == ZSTD_CONTENTSIZE_ERROR) {
    throw InputError(where + ": not a zstd frame (corrupt or truncated chunk)");
  }
  if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != expected) {
    throw InputError(where + ": zstd chunk declares " + std::to_string(declared) +
                     " bytes, expected " + std::to_string(expected));
  }
  std::vector<std::byte> out(expected);
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), in.data(), in.size());
  if (ZSTD_isError(n)) {
    throw InputError(where + ": corrupt or truncated zstd chunk (" + ZSTD_getErrorName(n) + ")");
  }
  if (n != expected) {
    throw InputError(where + ": zstd chunk decompressed to " + std::to_string(n) +
                     " bytes, expected " + std::to_string(expected));
  }
  return out;
}

std::vector<std::byte> bloscChunk(std::span<const std::byte> in, std::uint64_t expected,
                                  const std::string& where) {
  if (in.size() < BLOSC_MIN_HEADER_LENGTH) {
    throw InputError(where + ": truncated blosc chunk (" + std::to_string(in.size()) +
                     " bytes, shorter than the 16-byte header)");
  }
  std::size_t nbytes = 0, cbytes = 0, blocksize = 0;
  blosc_cbuffer_sizes(in.data(), &nbytes, &cbytes, &blocksize);
  if (cbytes != in.size()) {
    throw InputError(where + ": blosc header says " + std::to_string(cbytes) +
                     " compressed bytes, the chunk has " + std::to_string(in.size()) +
                     (cbytes > in.size() ? " (truncated)" : ""));
  }
  if (nbytes != expected) {
    throw InputError(where + ": blosc chunk holds " + std::to_string(nbytes) + " bytes, expected " +
                     std::to_string(expected));
  }
  std::size_t validated = 0;
  if (blosc_cbuffer_validate(in.data(), in.size(), &validated) != 0 || validated != expected) {
    throw InputError(where + ": corrupt blosc header");
  }
  std::vector<std::byte> out(expected);
  const int n = blosc_decompress_ctx(in.data(), out.data(), out.size(), 1);
  if (n < 0 || std::uint64_t(n) != expected) {
    throw InputError(where + ": corrupt blosc chunk (blosc_decompress returned " +
                     std::to_string(n) + ")");
  }
  return out;
}

}  // namespace

std::vector<std::byte> decodeZarrChunk(const ZarrArrayMeta& meta, std::span<const std::byte> stored,
                                       const std::string& where) {
  const std::uint64_t expected = meta.chunkBytes();
  if (stored.size() > meta.maxStoredChunkBytes()) {
    throw InputError(where + ": chunk of " + std::to_string(stored.size()) +
                     " bytes is larger than any encoding of " + std::to_string(expected) +
                     " bytes");
  }
  switch (meta.compressor) {
    case ZarrCompressor::None:
      if (stored.size() != expected) {
        throw InputError(where + ": uncompressed chunk has " + std::to_string(stored.size()) +
                         " bytes, expected " + std::to_string(expected));
      }
      return {stored.begin(), stored.end()};
    case ZarrCompressor::Zlib:
      return inflateChunk(stored, expected, false, where);
    case ZarrCompressor::Gzip:
      return inflateChunk(stored, expected, true, where);
    case ZarrCompressor::Zstd:
      return zstdChunk(stored, expected, where);
    case ZarrCompressor::Blosc:
      return bloscChunk(stored, expected, where);
  }
  throw Error(where + ": unknown compressor");
}

namespace {

std::vector<std::byte> deflateChunk(std::span<const std::byte> raw, bool gzip) {
  z_stream zs{};
  if (deflateInit2(&zs, 6, Z_DEFLATED, gzip ? 15 + 16 : 15, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw Error("zlib deflateInit failed");
  }
  std::vector<std::byte> out(deflateBound(&zs, static_cast<uLong>(raw.size())) + 32);
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(raw.data()));
  zs.avail_in = static_cast<uInt>(raw.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  const int ret = deflate(&zs, Z_FINISH);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  if (ret != Z_STREAM_END) throw Error("zlib deflate failed");
  return out;
}

}  // namespace

std::vector<std::byte> encodeZarrChunk(ZarrCompressor compressor, int itemSize,
                                       std::span<const std::byte> raw) {
  switch (compressor) {
    case ZarrCompressor::None:
      return {raw.begin(), raw.end()};
    case ZarrCompressor::Zlib:
      return deflateChunk(raw, false);
    case ZarrCompressor::Gzip:
      return deflateChunk(raw, true);
    case ZarrCompressor::Zstd: {
      std::vector<std::byte> out(ZSTD_compressBound(raw.size()));
      const std::size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), 3);
      if (ZSTD_isError(n)) throw Error(std::string("zstd: ") + ZSTD_getErrorName(n));
      out.resize(n);
      return out;
    }
    case ZarrCompressor::Blosc: {
      std::vector<std::byte> out(raw.size() + BLOSC_MAX_OVERHEAD);
      const int n =
          blosc_compress_ctx(5, BLOSC_SHUFFLE, static_cast<std::size_t>(itemSize), raw.size(),
                             raw.data(), out.data(), out.size(), BLOSC_LZ4_COMPNAME, 0, 1);
      if (n <= 0) throw Error("blosc_compress failed (" + std::to_string(n) + ")");
      out.resize(static_cast<std::size_t>(n));
      return out;
    }
  }
  throw Error("unknown compressor");
}

}  // namespace tessera

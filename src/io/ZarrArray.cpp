#include "tessera/io/ZarrArray.h"

#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "io/ZarrCodecs.h"
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
  if (const auto v = io_detail::zarrFillNumber(f)) return *v;
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
  std::string key = keyPrefix;
  for (std::size_t i = 0; i < index.size(); ++i) {
    if (i) key += separator;
    key += std::to_string(sharded() ? index[i] * chunks[i] / shard[i] : index[i]);
  }
  return key;
}

std::uint64_t ZarrArrayMeta::chunksPerShard() const {
  std::uint64_t n = 1;
  for (std::size_t a = 0; a < shard.size(); ++a) n *= std::uint64_t(shard[a] / chunks[a]);
  return n;
}

std::uint64_t ZarrArrayMeta::innerChunkIndex(std::span<const std::int64_t> index) const {
  std::uint64_t linear = 0;
  for (std::size_t a = 0; a < shard.size(); ++a) {
    const std::int64_t per = shard[a] / chunks[a];
    linear = linear * std::uint64_t(per) + std::uint64_t(index[a] % per);
  }
  return linear;
}

std::optional<double> io_detail::zarrFillNumber(const json& f) {
  if (f.is_boolean()) return f.get<bool>() ? 1.0 : 0.0;
  if (f.is_number()) return f.get<double>();
  if (f.is_string()) {
    const std::string s = f.get<std::string>();
    if (s == "NaN") return std::numeric_limits<double>::quiet_NaN();
    if (s == "Infinity") return std::numeric_limits<double>::infinity();
    if (s == "-Infinity") return -std::numeric_limits<double>::infinity();
  }
  return std::nullopt;
}

json io_detail::parseZarrDocument(std::string_view text, const std::string& name, int format) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(name + ": not valid JSON (" + e.what() + ")");
  }
  if (!doc.is_object()) throw InputError(name + ": not a JSON object");
  if (!doc.contains("zarr_format") || doc["zarr_format"] != format) {
    throw InputError(name + ": zarr_format is " +
                     (doc.contains("zarr_format") ? doc["zarr_format"].dump() : "missing") +
                     ", expected " + std::to_string(format) + " (Zarr v" + std::to_string(format) +
                     ")");
  }
  return doc;
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
  json doc = io_detail::parseZarrDocument(text, name, 2);
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

std::vector<std::byte> decodedZarrChunk(const ZarrArrayMeta& meta, std::vector<std::byte> raw,
                                        const std::string& where) {
  if (meta.format == 3) return io_detail::decodedZarrV3Chunk(meta, std::move(raw), where);
  if (raw.size() != meta.chunkBytes()) {
    throw InputError(where + ": decoded " + meta.compressorText + " chunk has " +
                     std::to_string(raw.size()) + " bytes, expected " +
                     std::to_string(meta.chunkBytes()));
  }
  return raw;
}

std::vector<std::byte> decodeZarrChunk(const ZarrArrayMeta& meta, std::span<const std::byte> stored,
                                       const std::string& where) {
  if (meta.format == 3) return io_detail::decodeZarrV3Chunk(meta, stored, where);
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
      return io_detail::inflateZarrChunk(stored, expected, false, where);
    case ZarrCompressor::Gzip:
      return io_detail::inflateZarrChunk(stored, expected, true, where);
    case ZarrCompressor::Zstd:
      return io_detail::zstdZarrChunk(stored, expected, where);
    case ZarrCompressor::Blosc:
      return io_detail::bloscZarrChunk(stored, expected, where);
  }
  throw Error(where + ": unknown compressor");
}

}  // namespace tessera

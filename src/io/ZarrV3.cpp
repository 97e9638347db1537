// Zarr v3 arrays (io/ZarrArray.h): the array `zarr.json`, the codec
// pipeline's decoding, the sharding codec's index and the crc32c codec.
// Spec: Zarr core specification 3.0 ("Array metadata", "Chunk grids",
// "Chunk key encoding", "Codecs"), the codec specs (bytes, transpose, gzip,
// zstd, blosc, crc32c) and sharding_indexed ("Binary shard format").
#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include <nlohmann/json.hpp>

#include "io/ZarrCodecs.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/ZarrArray.h"

namespace tessera {

namespace {

using nlohmann::json;

// Largest accepted inner-chunks-per-shard: its index alone is 16 B each.
constexpr std::uint64_t kMaxChunksPerShard = 1u << 20;

std::uint64_t readLe64(const std::byte* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | std::uint64_t(p[i]);
  return v;
}

void writeLe(std::vector<std::byte>& out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(std::byte((v >> (8 * i)) & 0xff));
}

struct DataType {
  const char* name;
  char kind;
  int size;
};
constexpr DataType kDataTypes[] = {
    {"bool", 'b', 1},   {"int8", 'i', 1},    {"int16", 'i', 2},   {"int32", 'i', 4},
    {"int64", 'i', 8},  {"uint8", 'u', 1},   {"uint16", 'u', 2},  {"uint32", 'u', 4},
    {"uint64", 'u', 8}, {"float32", 'f', 4}, {"float64", 'f', 8},
};

void parseDataType(const json& j, const std::string& name, ZarrArrayMeta& m) {
  const std::string d = j.is_string() ? j.get<std::string>() : j.dump();
  for (const DataType& t : kDataTypes) {
    if (d != t.name) continue;
    m.dtype = d;
    m.kind = t.kind;
    m.itemSize = t.size;
    const bool own = (t.kind == 'u' && t.size <= 2) || (t.kind == 'i' && t.size == 2) ||
                     (t.kind == 'f' && t.size == 4);
    m.target = t.kind == 'u' && t.size == 1   ? ScalarType::U8
               : t.kind == 'u' && t.size == 2 ? ScalarType::U16
               : t.kind == 'i' && t.size == 2 ? ScalarType::I16
                                              : ScalarType::F32;
    m.converted = !own;
    return;
  }
  throw InputError(name + ": data_type " + j.dump() +
                   " is not supported (bool, int8..int64, uint8..uint64, float32, float64)");
}

std::vector<std::int64_t> positiveInts(const json& v, const std::string& what,
                                       const std::string& name) {
  if (!v.is_array()) throw InputError(name + ": " + what + " must be a list of integers");
  std::vector<std::int64_t> out;
  for (const json& x : v) {
    if (!x.is_number_integer() || x.get<std::int64_t>() <= 0 ||
        x.get<std::int64_t>() > (std::int64_t{1} << 40)) {
      throw InputError(name + ": " + what + " " + v.dump() +
                       " holds a value that is not a positive integer (up to 2^40)");
    }
    out.push_back(x.get<std::int64_t>());
  }
  return out;
}

double parseFillV3(const json& f, const ZarrArrayMeta& m, const std::string& name) {
  if (const auto v = io_detail::zarrFillNumber(f)) return *v;
  if (f.is_string()) {
    const std::string s = f.get<std::string>();
    // A float's bytes as hex ("0x7fc00000"), big-endian digits.
    if (m.kind == 'f' && s.size() == 2 + 2 * std::size_t(m.itemSize) && s.rfind("0x", 0) == 0) {
      std::uint64_t bits = 0;
      const char* end = s.data() + s.size();
      const auto [at, ec] = std::from_chars(s.data() + 2, end, bits, 16);
      if (ec == std::errc() && at == end) {
        // memcpy, not std::bit_cast: emscripten's libc++ here lacks it.
        if (m.itemSize == 4) {
          const auto narrow = static_cast<std::uint32_t>(bits);
          float f32 = 0.0f;
          std::memcpy(&f32, &narrow, sizeof f32);
          return double(f32);
        }
        double f64 = 0.0;
        std::memcpy(&f64, &bits, sizeof f64);
        return f64;
      }
    }
  }
  throw InputError(name + ": fill_value " + f.dump() + " is not a number of data_type " + m.dtype);
}

std::string codecName(const json& c, const std::string& where) {
  if (c.is_string()) return c.get<std::string>();
  if (c.is_object() && c.contains("name") && c["name"].is_string()) {
    return c["name"].get<std::string>();
  }
  throw InputError(where + " " + c.dump() + " has no \"name\"");
}

json codecConfig(const json& c) {
  return c.is_object() && c.contains("configuration") && c["configuration"].is_object()
             ? c["configuration"]
             : json::object();
}

std::string bloscText(const json& cfg) {
  const std::string cname = cfg.value("cname", std::string("?"));
  std::string shuffle = "shuffle";
  if (cfg.contains("shuffle") && cfg["shuffle"].is_string()) {
    shuffle = cfg["shuffle"].get<std::string>();
  }
  return "blosc " + cname + " " + shuffle;
}

// A codec list: array->array (transpose), one array->bytes (bytes or
// sharding_indexed), then bytes->bytes. `inner`: a shard's inner list,
// where another sharding_indexed is refused (nesting is not read).
std::string parseCodecs(const json& list, const std::string& field, const std::string& name,
                        ZarrArrayMeta& m, bool inner);

std::string parseSharding(const json& cfg, const std::string& where, const std::string& name,
                          ZarrArrayMeta& m) {
  if (!cfg.contains("chunk_shape")) throw InputError(name + ": " + where + " has no chunk_shape");
  const std::vector<std::int64_t> inner =
      positiveInts(cfg["chunk_shape"], where + ".chunk_shape", name);
  if (inner.size() != m.shape.size()) {
    throw InputError(name + ": " + where + ".chunk_shape " + cfg["chunk_shape"].dump() + " has " +
                     std::to_string(inner.size()) + " axes, the array " +
                     std::to_string(m.shape.size()));
  }
  std::uint64_t per = 1;
  for (std::size_t a = 0; a < inner.size(); ++a) {
    if (m.chunks[a] % inner[a] != 0) {
      throw InputError(name + ": " + where + ".chunk_shape " + cfg["chunk_shape"].dump() +
                       " does not divide the shard shape (chunk_grid) evenly");
    }
    per *= std::uint64_t(m.chunks[a] / inner[a]);
    if (per > kMaxChunksPerShard) {
      throw InputError(name + ": " + where + ": more than 2^20 inner chunks per shard");
    }
  }
  m.shard = m.chunks;
  m.chunks = inner;
  const std::string location = cfg.value("index_location", std::string("end"));
  if (location != "end" && location != "start") {
    throw InputError(name + ": " + where + ".index_location \"" + location +
                     "\" is neither \"start\" nor \"end\"");
  }
  m.indexAtEnd = location == "end";
  const std::string text =
      parseCodecs(cfg.contains("codecs") ? cfg["codecs"] : json::array({{{"name", "bytes"}}}),
                  where + ".codecs", name, m, true);
  // The index: uint64 little-endian pairs, optionally a crc32c after.
  const json& idx = cfg.contains("index_codecs") ? cfg["index_codecs"] : json::array();
  if (!idx.is_array()) throw InputError(name + ": " + where + ".index_codecs is not a list");
  for (std::size_t i = 0; i < idx.size(); ++i) {
    const std::string n = codecName(idx[i], name + ": " + where + ".index_codecs");
    const json c = codecConfig(idx[i]);
    if (n == "bytes" && c.value("endian", std::string("little")) == "little") continue;
    if (n == "crc32c" && i + 1 == idx.size()) {
      m.indexCrc32c = true;
      continue;
    }
    throw InputError(name + ": " + where + ".index_codecs[" + std::to_string(i) + "] " +
                     idx[i].dump() +
                     " is not read (the index is read as bytes little-endian, then crc32c)");
  }
  return text;
}

// Returns the pipeline for `info` ("zstd + crc32c").
std::string parseCodecs(const json& list, const std::string& field, const std::string& name,
                        ZarrArrayMeta& m, bool inner) {
  if (!list.is_array() || list.empty()) {
    throw InputError(name + ": " + field + " must be a non-empty list of codecs");
  }
  bool haveBytes = false;
  int compressors = 0;
  std::string text;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = field + "[" + std::to_string(i) + "]";
    const std::string n = codecName(list[i], name + ": " + where);
    const json c = codecConfig(list[i]);
    const auto order = [&](bool wantBytes) {
      if (haveBytes != wantBytes) {
        throw InputError(name + ": " + where + " \"" + n + "\" is out of order (" +
                         (wantBytes ? "a bytes-to-bytes codec before the array-to-bytes codec"
                                    : "an array codec after the array-to-bytes codec") +
                         ")");
      }
    };
    if (n == "transpose") {
      order(false);
      const std::size_t rank = m.shape.size();
      std::vector<int> perm;
      const json& o = c.contains("order") ? c["order"] : json();
      if (o.is_string() && (o == "C" || o == "F")) {
        for (std::size_t a = 0; a < rank; ++a) perm.push_back(int(o == "C" ? a : rank - 1 - a));
      } else if (o.is_array() && o.size() == rank) {
        std::vector<bool> seen(rank, false);
        for (const json& x : o) {
          if (!x.is_number_integer() || x.get<std::int64_t>() < 0 ||
              x.get<std::uint64_t>() >= rank || seen[x.get<std::size_t>()]) {
            throw InputError(name + ": " + where + ".order " + o.dump() +
                             " is not a permutation of 0.." + std::to_string(rank - 1));
          }
          seen[x.get<std::size_t>()] = true;
          perm.push_back(x.get<int>());
        }
      } else {
        throw InputError(name + ": " + where + ".order " + o.dump() + " is not a permutation of " +
                         std::to_string(rank) + " axes");
      }
      if (!m.transpose.empty()) {
        throw InputError(name + ": " + where + ": a second transpose is not read");
      }
      m.transpose = perm;
    } else if (n == "bytes") {
      order(false);
      haveBytes = true;
      const std::string endian = c.value("endian", std::string(m.itemSize == 1 ? "little" : ""));
      if (endian != "little" && endian != "big") {
        throw InputError(name + ": " + where + ".endian " +
                         (c.contains("endian") ? c["endian"].dump() : std::string("missing")) +
                         " (a " + m.dtype + " array needs \"little\" or \"big\")");
      }
      m.bigEndian = endian == "big" && m.itemSize > 1;
    } else if (n == "sharding_indexed") {
      order(false);
      if (inner) {
        throw InputError(name + ": " + where + ": nested sharding_indexed is not read");
      }
      if (!m.transpose.empty()) {
        throw InputError(name + ": " + where + ": transpose before sharding_indexed is not read");
      }
      haveBytes = true;
      const std::string innerText = parseSharding(c, where + ".configuration", name, m);
      text = "sharded (" + std::to_string(m.chunksPerShard()) + " chunks/shard) " + innerText;
    } else if ((n == "gzip" || n == "zstd" || n == "blosc" || n == "crc32c") && m.sharded() &&
               !inner) {
      throw InputError(name + ": " + where + " \"" + n +
                       "\" after sharding_indexed is not read (it would take whole shards)");
    } else if (n == "gzip" || n == "zstd" || n == "blosc") {
      order(true);
      if (++compressors > 1 || !m.bytesCodecs.empty()) {
        // Sizes between two compressors are unknown: a chunk's size could
        // not be checked before it is held.
        throw InputError(name + ": " + where + " \"" + n +
                         "\": one compressor per chunk, and crc32c after it, are read");
      }
      m.bytesCodecs.push_back(n == "gzip"   ? ZarrBytesCodec::Gzip
                              : n == "zstd" ? ZarrBytesCodec::Zstd
                                            : ZarrBytesCodec::Blosc);
      m.compressor = n == "gzip"   ? ZarrCompressor::Gzip
                     : n == "zstd" ? ZarrCompressor::Zstd
                                   : ZarrCompressor::Blosc;
      text += n == "blosc" ? bloscText(c) : n;
    } else if (n == "crc32c") {
      order(true);
      m.bytesCodecs.push_back(ZarrBytesCodec::Crc32c);
      text += text.empty() ? "crc32c" : " + crc32c";
    } else {
      throw InputError(name + ": " + where + " codec \"" + n +
                       "\" is not supported (transpose, bytes, gzip, zstd, blosc, crc32c, "
                       "sharding_indexed)");
    }
  }
  if (!haveBytes) {
    throw InputError(name + ": " + field +
                     " has no array-to-bytes codec (bytes or sharding_indexed)");
  }
  return text.empty() ? "raw" : text;
}

ZarrArrayMeta parseZarrJsonFields(std::string_view text, const std::string& name) {
  json doc = io_detail::parseZarrDocument(text, name, 3);
  if (doc.value("node_type", std::string()) != "array") {
    throw InputError(name + ": node_type is " +
                     (doc.contains("node_type") ? doc["node_type"].dump() : "missing") +
                     ", expected \"array\"");
  }
  ZarrArrayMeta m;
  m.format = 3;
  m.separator = '/';
  m.shape = positiveInts(doc.contains("shape") ? doc["shape"] : json(), "shape", name);
  if (m.shape.empty() || m.shape.size() > 5) {
    throw InputError(name + ": shape has " + std::to_string(m.shape.size()) +
                     " axes (expected 1 to 5)");
  }
  if (!doc.contains("data_type")) throw InputError(name + ": no data_type");
  parseDataType(doc["data_type"], name, m);
  const json& grid = doc.contains("chunk_grid") ? doc["chunk_grid"] : json();
  if (!grid.is_object() || grid.value("name", std::string()) != "regular") {
    throw InputError(name + ": chunk_grid " + grid.dump() +
                     " is not read (only the \"regular\" chunk grid)");
  }
  const json cfg = codecConfig(grid);
  m.chunks = positiveInts(cfg.contains("chunk_shape") ? cfg["chunk_shape"] : json(),
                          "chunk_grid.configuration.chunk_shape", name);
  if (m.chunks.size() != m.shape.size()) {
    throw InputError(name + ": chunk_grid.configuration.chunk_shape has " +
                     std::to_string(m.chunks.size()) + " axes, shape " +
                     std::to_string(m.shape.size()));
  }
  const json& enc = doc.contains("chunk_key_encoding") ? doc["chunk_key_encoding"] : json();
  const std::string encoding = enc.is_object() ? enc.value("name", std::string()) : "";
  if (encoding != "default" && encoding != "v2") {
    throw InputError(name + ": chunk_key_encoding " + enc.dump() +
                     " is not read (\"default\" or \"v2\")");
  }
  const json ecfg = codecConfig(enc);
  const std::string sep = ecfg.contains("separator") && ecfg["separator"].is_string()
                              ? ecfg["separator"].get<std::string>()
                              : (encoding == "default" ? "/" : ".");
  if (sep != "/" && sep != ".") {
    throw InputError(name + ": chunk_key_encoding.configuration.separator \"" + sep +
                     "\" is neither \"/\" nor \".\"");
  }
  m.separator = sep[0];
  m.keyPrefix = encoding == "default" ? "c" + sep : "";
  if (doc.contains("storage_transformers") &&
      !(doc["storage_transformers"].is_array() && doc["storage_transformers"].empty())) {
    throw InputError(name + ": storage_transformers " + doc["storage_transformers"].dump() +
                     " are not read");
  }
  for (const auto& [key, value] : doc.items()) {
    // An extension the reader must understand and does not: refused.
    if (value.is_object() && value.contains("must_understand") &&
        value["must_understand"] != false && key != "attributes") {
      throw InputError(name + ": extension \"" + key + "\" must be understood and is not");
    }
  }
  if (!doc.contains("fill_value")) throw InputError(name + ": no fill_value");
  m.fill = parseFillV3(doc["fill_value"], m, name);
  m.compressorText =
      parseCodecs(doc.contains("codecs") ? doc["codecs"] : json(), "codecs", name, m, false);
  // Saturating products, as for v2.
  long double elements = 1.0L;
  for (std::int64_t c : m.chunks) elements *= static_cast<long double>(c);
  if (elements * m.itemSize > 1.0e15L) {
    throw BudgetError(name + ": chunks of " + m.dtype + " are larger than any host can hold");
  }
  HostBudget::global().check(m.chunkBytes(), name + ": one chunk");
  return m;
}

// Decoded element order -> C order of the chunk: encoded axis i is the
// decoded axis order[i] (transpose codec).
std::vector<std::byte> untranspose(const ZarrArrayMeta& m, std::vector<std::byte> enc) {
  const std::size_t rank = m.chunks.size();
  std::vector<std::int64_t> estride(rank, 1);
  for (std::size_t i = rank - 1; i-- > 0;) {
    estride[i] = estride[i + 1] * m.chunks[std::size_t(m.transpose[i + 1])];
  }
  std::vector<std::int64_t> stride(rank, 0);  // per decoded axis, in the encoded array
  for (std::size_t i = 0; i < rank; ++i) stride[std::size_t(m.transpose[i])] = estride[i];
  std::vector<std::byte> out(enc.size());
  std::vector<std::int64_t> d(rank, 0);
  const std::size_t item = std::size_t(m.itemSize);
  const std::uint64_t n = m.chunkElements();
  for (std::uint64_t e = 0; e < n; ++e) {
    std::int64_t src = 0;
    for (std::size_t a = 0; a < rank; ++a) src += d[a] * stride[a];
    std::memcpy(out.data() + e * item, enc.data() + std::size_t(src) * item, item);
    for (std::size_t a = rank; a-- > 0;) {
      if (++d[a] < m.chunks[a]) break;
      d[a] = 0;
    }
  }
  return out;
}

void checkCrc(std::span<const std::byte> in, const std::string& where, const char* what) {
  if (in.size() < 4) {
    throw InputError(where + ": " + what + " of " + std::to_string(in.size()) +
                     " bytes is shorter than its crc32c");
  }
  std::uint32_t stored = 0;
  for (int i = 3; i >= 0; --i) stored = (stored << 8) | std::uint32_t(in[in.size() - 4 + i]);
  const std::uint32_t computed = crc32c(in.first(in.size() - 4));
  if (stored != computed) {
    char buf[96];
    std::snprintf(buf, sizeof buf, ": crc32c mismatch (stored 0x%08x, computed 0x%08x)", stored,
                  computed);
    throw InputError(where + ": " + what + buf);
  }
}

}  // namespace

std::uint32_t crc32c(std::span<const std::byte> bytes) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0x82F63B78u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::byte b : bytes) c = table[(c ^ std::uint32_t(b)) & 0xff] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

ZarrArrayMeta parseZarrJsonArray(std::string_view text, const std::string& name) {
  try {
    return parseZarrJsonFields(text, name);
  } catch (const json::exception& e) {
    throw InputError(name + ": a field has the wrong type or value (" + e.what() + ")");
  }
}

namespace io_detail {

std::vector<std::byte> decodeZarrV3Chunk(const ZarrArrayMeta& m, std::span<const std::byte> stored,
                                         const std::string& where) {
  const std::uint64_t expected = m.chunkBytes();
  if (stored.size() > m.maxStoredChunkBytes()) {
    throw InputError(where + ": chunk of " + std::to_string(stored.size()) +
                     " bytes is larger than any encoding of " + std::to_string(expected) +
                     " bytes");
  }
  // Sizes before each bytes-to-bytes codec: known up to the compressor,
  // which is first (parseCodecs), so each decoder knows what to expect.
  std::vector<std::uint64_t> before(m.bytesCodecs.size() + 1, expected);
  for (std::size_t i = 0; i < m.bytesCodecs.size(); ++i) {
    before[i + 1] = m.bytesCodecs[i] == ZarrBytesCodec::Crc32c ? before[i] + 4 : 0;
  }
  std::vector<std::byte> buf(stored.begin(), stored.end());
  for (std::size_t i = m.bytesCodecs.size(); i-- > 0;) {
    switch (m.bytesCodecs[i]) {
      case ZarrBytesCodec::Crc32c:
        checkCrc(buf, where, "chunk");
        buf.erase(buf.end() - 4, buf.end());  // checkCrc made sure it has 4
        break;
      case ZarrBytesCodec::Gzip:
        buf = inflateZarrChunk(buf, before[i], true, where);
        break;
      case ZarrBytesCodec::Zstd:
        buf = zstdZarrChunk(buf, before[i], where);
        break;
      case ZarrBytesCodec::Blosc:
        buf = bloscZarrChunk(buf, before[i], where);
        break;
    }
  }
  if (buf.size() != expected) {
    throw InputError(where + ": " + (m.bytesCodecs.empty() ? "uncompressed " : "decoded ") +
                     "chunk has " + std::to_string(buf.size()) + " bytes, expected " +
                     std::to_string(expected) + " (" + m.dtype + " chunk)");
  }
  if (!m.transpose.empty()) return untranspose(m, std::move(buf));
  return buf;
}

std::vector<std::byte> decodedZarrV3Chunk(const ZarrArrayMeta& m, std::vector<std::byte> raw,
                                          const std::string& where) {
  if (raw.size() != m.chunkBytes()) {
    throw InputError(where + ": decoded " + m.compressorText + " chunk has " +
                     std::to_string(raw.size()) + " bytes, expected " +
                     std::to_string(m.chunkBytes()) + " (" + m.dtype + " chunk)");
  }
  if (!m.transpose.empty()) return untranspose(m, std::move(raw));
  return raw;
}

}  // namespace io_detail

std::vector<ZarrShardEntry> parseShardIndex(const ZarrArrayMeta& m,
                                            std::span<const std::byte> index,
                                            std::uint64_t shardBytes, const std::string& where) {
  const std::uint64_t n = m.chunksPerShard();
  if (index.size() != m.shardIndexBytes()) {
    throw InputError(where + ": shard index of " + std::to_string(index.size()) +
                     " bytes, expected " + std::to_string(m.shardIndexBytes()) + " (" +
                     std::to_string(n) + " inner chunks)");
  }
  if (shardBytes < index.size()) {
    throw InputError(where + ": shard of " + std::to_string(shardBytes) +
                     " bytes is shorter than its " + std::to_string(index.size()) + "-byte index");
  }
  if (m.indexCrc32c) checkCrc(index, where, "shard index");
  // Where inner chunks may lie: the shard less its index.
  const std::uint64_t lo = m.indexAtEnd ? 0 : index.size();
  const std::uint64_t hi = m.indexAtEnd ? shardBytes - index.size() : shardBytes;
  const std::uint64_t most = m.maxStoredChunkBytes();
  std::vector<ZarrShardEntry> entries(n);
  std::vector<std::uint64_t> present;
  for (std::uint64_t i = 0; i < n; ++i) {
    ZarrShardEntry& e = entries[i];
    e.offset = readLe64(index.data() + 16 * i);
    e.bytes = readLe64(index.data() + 16 * i + 8);
    if (e.missing()) continue;
    const std::string entry = where + ": shard index entry " + std::to_string(i) + " (offset " +
                              std::to_string(e.offset) + ", " + std::to_string(e.bytes) + " bytes)";
    if (e.bytes == 0 || e.bytes > most) {
      throw InputError(entry + ": an inner chunk holds 1.." + std::to_string(most) + " bytes");
    }
    if (e.offset < lo || e.offset > hi || e.bytes > hi - e.offset) {
      throw InputError(entry + " lies outside the shard's chunk bytes [" + std::to_string(lo) +
                       ", " + std::to_string(hi) + ") of " + std::to_string(shardBytes));
    }
    present.push_back(i);
  }
  std::sort(present.begin(), present.end(), [&](std::uint64_t a, std::uint64_t b) {
    return entries[a].offset < entries[b].offset;
  });
  for (std::size_t k = 1; k < present.size(); ++k) {
    const ZarrShardEntry& a = entries[present[k - 1]];
    const ZarrShardEntry& b = entries[present[k]];
    if (a.offset + a.bytes > b.offset) {
      throw InputError(where + ": shard index entries " + std::to_string(present[k - 1]) + " and " +
                       std::to_string(present[k]) + " overlap (bytes " + std::to_string(a.offset) +
                       "+" + std::to_string(a.bytes) + " and " + std::to_string(b.offset) + "+" +
                       std::to_string(b.bytes) + ")");
    }
  }
  return entries;
}

std::vector<std::byte> encodeShardIndex(const std::vector<ZarrShardEntry>& entries) {
  std::vector<std::byte> out;
  out.reserve(entries.size() * 16 + 4);
  for (const ZarrShardEntry& e : entries) {
    writeLe(out, e.offset, 8);
    writeLe(out, e.bytes, 8);
  }
  writeLe(out, crc32c(out), 4);
  return out;
}

std::string zarrJsonArray(const std::vector<std::int64_t>& shape,
                          const std::vector<std::int64_t>& chunks,
                          const std::vector<std::int64_t>& shard, ScalarType type,
                          ZarrCompressor compressor) {
  const int item = int(bytesPerVoxel(type));
  json codecs = json::array();
  codecs.push_back({{"name", "bytes"}, {"configuration", {{"endian", "little"}}}});
  switch (compressor) {
    case ZarrCompressor::None:
      break;
    case ZarrCompressor::Zlib:  // v3 has no zlib codec: gzip, the same deflate
    case ZarrCompressor::Gzip:
      codecs.push_back({{"name", "gzip"}, {"configuration", {{"level", 6}}}});
      break;
    case ZarrCompressor::Zstd:
      codecs.push_back({{"name", "zstd"}, {"configuration", {{"level", 3}, {"checksum", false}}}});
      break;
    case ZarrCompressor::Blosc:
      codecs.push_back({{"name", "blosc"},
                        {"configuration",
                         {{"cname", "lz4"},
                          {"clevel", 5},
                          {"shuffle", "shuffle"},
                          {"typesize", item},
                          {"blocksize", 0}}}});
      break;
  }
  json doc;
  doc["zarr_format"] = 3;
  doc["node_type"] = "array";
  doc["shape"] = shape;
  doc["data_type"] = type == ScalarType::U8    ? "uint8"
                     : type == ScalarType::U16 ? "uint16"
                     : type == ScalarType::I16 ? "int16"
                                               : "float32";
  doc["chunk_grid"] = {{"name", "regular"},
                       {"configuration", {{"chunk_shape", shard.empty() ? chunks : shard}}}};
  doc["chunk_key_encoding"] = {{"name", "default"}, {"configuration", {{"separator", "/"}}}};
  doc["fill_value"] = 0;
  if (shard.empty()) {
    doc["codecs"] = codecs;
  } else {
    doc["codecs"] = json::array(
        {{{"name", "sharding_indexed"},
          {"configuration",
           {{"chunk_shape", chunks},
            {"codecs", codecs},
            {"index_codecs",
             json::array({{{"name", "bytes"}, {"configuration", {{"endian", "little"}}}},
                          {{"name", "crc32c"}}})},
            {"index_location", "end"}}}}});
  }
  doc["dimension_names"] = shape.size() == 3 ? json::array({"z", "y", "x"}) : json();
  if (doc["dimension_names"].is_null()) doc.erase("dimension_names");
  doc["attributes"] = json::object();
  return doc.dump(2);
}

}  // namespace tessera

// Zarr v3 / OME-NGFF 0.5: stores built byte by byte from the spec (the
// codec pipeline, sharding with the index at either end, missing inner
// chunks), Tessera's own v3 stores (sharded and not) read back equal to the
// v2 store of the same volume, corrupt shards and metadata refused with a
// message naming the key, and the level translations NGFF readers see.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <fstream>
#include <mutex>
#include <set>

#include <nlohmann/json.hpp>

#include "io/ZarrTestSupport.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/ZarrArray.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/io/ZarrWriter.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::TempDir;

std::vector<std::byte> bytesOf(const std::string& s) {
  std::vector<std::byte> b(s.size());
  std::memcpy(b.data(), s.data(), s.size());
  return b;
}

void appendLe(std::vector<std::byte>& out, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) out.push_back(std::byte((v >> (8 * i)) & 0xff));
}

bool sameVoxels(const Volume& a, const Volume& b) {
  return a.dims() == b.dims() && a.type() == b.type() &&
         std::memcmp(a.bytes().data(), b.bytes().data(), a.byteSize()) == 0;
}

// The value at (x, y, z) of the hand-built arrays.
std::uint16_t valueAt(int x, int y, int z) {
  return std::uint16_t(1000 + 100 * z + 10 * y + x);
}

// A z,y,x = 6x5x7 uint16 array in 4^3 shards of 2^3 inner chunks, as the
// sharding spec lays them out: inner chunks `codecs` (a transpose of the
// axes, big-endian bytes, gzip, crc32c as chosen), the index at `location`,
// inner chunks listed in `skip` left out (fill_value 7).
struct HandShards {
  bool transpose = false;
  bool bigEndian = false;
  bool gzip = false;
  bool crc = false;
  bool indexAtStart = false;
  std::vector<int> skip;  // inner chunk numbers (of shard 0) left out

  json codecs() const {
    json c = json::array();
    if (transpose) c.push_back({{"name", "transpose"}, {"configuration", {{"order", {2, 1, 0}}}}});
    c.push_back({{"name", "bytes"}, {"configuration", {{"endian", bigEndian ? "big" : "little"}}}});
    if (gzip) c.push_back({{"name", "gzip"}, {"configuration", {{"level", 5}}}});
    if (crc) c.push_back({{"name", "crc32c"}});
    return c;
  }
  std::string arrayJson() const {
    json doc = {
        {"zarr_format", 3},
        {"node_type", "array"},
        {"shape", {6, 5, 7}},
        {"data_type", "uint16"},
        {"chunk_grid", {{"name", "regular"}, {"configuration", {{"chunk_shape", {4, 4, 4}}}}}},
        {"chunk_key_encoding", {{"name", "default"}, {"configuration", {{"separator", "/"}}}}},
        {"fill_value", 7},
        {"codecs",
         {{{"name", "sharding_indexed"},
           {"configuration",
            {{"chunk_shape", {2, 2, 2}},
             {"codecs", codecs()},
             {"index_codecs",
              {{{"name", "bytes"}, {"configuration", {{"endian", "little"}}}},
               {{"name", "crc32c"}}}},
             {"index_location", indexAtStart ? "start" : "end"}}}}}},
        {"dimension_names", {"z", "y", "x"}}};
    return doc.dump();
  }
  // One inner chunk (2x2x2) at shard sx,sy,sz, inner ix,iy,iz, encoded.
  std::vector<std::byte> innerChunk(glm::ivec3 s, glm::ivec3 i) const {
    std::vector<std::uint16_t> v;  // in the encoded order
    for (int a = 0; a < 2; ++a) {
      for (int b = 0; b < 2; ++b) {
        for (int c = 0; c < 2; ++c) {
          // C order z,y,x; transposed [2,1,0]: x,y,z (x slowest).
          const int z = transpose ? c : a, y = b, x = transpose ? a : c;
          const glm::ivec3 p = s * 4 + i * 2 + glm::ivec3(x, y, z);
          v.push_back(p.x < 7 && p.y < 5 && p.z < 6 ? valueAt(p.x, p.y, p.z) : 7);
        }
      }
    }
    std::vector<std::byte> raw;
    for (std::uint16_t e : v) {
      if (bigEndian) {
        raw.push_back(std::byte(e >> 8));
        raw.push_back(std::byte(e & 0xff));
      } else {
        raw.push_back(std::byte(e & 0xff));
        raw.push_back(std::byte(e >> 8));
      }
    }
    if (gzip) raw = encodeZarrChunk(ZarrCompressor::Gzip, 2, raw);
    if (crc) appendLe(raw, crc32c(raw), 4);
    return raw;
  }
  std::vector<std::byte> shard(glm::ivec3 s) const {
    std::vector<std::byte> chunks, index;
    const std::uint64_t indexBytes = 8 * 16 + 4;
    const std::uint64_t base = indexAtStart ? indexBytes : 0;
    for (int n = 0; n < 8; ++n) {
      const glm::ivec3 i(n % 2, (n / 2) % 2, n / 4);
      if (s == glm::ivec3(0) && std::find(skip.begin(), skip.end(), n) != skip.end()) {
        appendLe(index, ~std::uint64_t{0}, 8);
        appendLe(index, ~std::uint64_t{0}, 8);
        continue;
      }
      const std::vector<std::byte> c = innerChunk(s, i);
      appendLe(index, base + chunks.size(), 8);
      appendLe(index, c.size(), 8);
      chunks.insert(chunks.end(), c.begin(), c.end());
    }
    appendLe(index, crc32c(index), 4);
    if (indexAtStart) {
      index.insert(index.end(), chunks.begin(), chunks.end());
      return index;
    }
    chunks.insert(chunks.end(), index.begin(), index.end());
    return chunks;
  }
  std::shared_ptr<MemoryStorage> storage() const {
    auto m = std::make_shared<MemoryStorage>("mem://hand.zarr");
    m->put("zarr.json", bytesOf(arrayJson()));
    for (int sz = 0; sz < 2; ++sz) {
      for (int sy = 0; sy < 2; ++sy) {
        for (int sx = 0; sx < 2; ++sx) {
          m->put("c/" + std::to_string(sz) + "/" + std::to_string(sy) + "/" + std::to_string(sx),
                 shard({sx, sy, sz}));
        }
      }
    }
    return m;
  }
};

void expectHandValues(const Volume& v, const std::vector<int>& skipped) {
  ASSERT_EQ(v.dims(), glm::ivec3(7, 5, 6));
  ASSERT_EQ(v.type(), ScalarType::U16);
  int mismatches = 0;
  for (int z = 0; z < 6; ++z) {
    for (int y = 0; y < 5; ++y) {
      for (int x = 0; x < 7; ++x) {
        const bool inShard0 = x < 4 && y < 4 && z < 4;
        const int n = (x / 2) + 2 * (y / 2) + 4 * (z / 2);
        const bool gone = inShard0 && std::find(skipped.begin(), skipped.end(), n) != skipped.end();
        const double want = gone ? 7.0 : valueAt(x, y, z);
        if (v.valueAt(x, y, z) != want) ++mismatches;
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(ZarrV3, HandBuiltShardsReadForEveryCodecChainAndIndexLocation) {
  for (int variant = 0; variant < 6; ++variant) {
    SCOPED_TRACE(variant);
    HandShards h;
    h.transpose = variant == 1 || variant == 5;
    h.bigEndian = variant == 2 || variant == 5;
    h.gzip = variant == 3 || variant == 5;
    h.crc = variant == 4 || variant == 5;
    h.indexAtStart = variant % 2 == 1;
    h.skip = {1, 6};
    const ZarrStore store(h.storage());
    EXPECT_EQ(store.zarrFormat(), 3);
    EXPECT_EQ(store.level(0).chunk, glm::ivec3(2));
    expectHandValues(store.readLevel(0), h.skip);
  }
}

TEST(ZarrV3, AMissingShardIsFillValueAndKeysFollowTheEncoding) {
  HandShards h;
  auto m = h.storage();
  auto fresh = std::make_shared<MemoryStorage>("mem://hand.zarr");
  for (const char* k :
       {"zarr.json", "c/0/0/0", "c/0/0/1", "c/0/1/0", "c/0/1/1", "c/1/0/0", "c/1/0/1", "c/1/1/0"}) {
    fresh->put(k, *m->get(k, 1 << 20));
  }
  const ZarrStore store(fresh);
  const Volume v = store.readLevel(0);
  EXPECT_EQ(v.valueAt(6, 4, 5), 7.0);  // in shard (1,1,1)
  EXPECT_EQ(v.valueAt(3, 3, 3), valueAt(3, 3, 3));
  EXPECT_EQ(store.chunkKeys(0, {0, 0, 0}, {7, 5, 6}).size(), 8u);  // shards, not inner chunks
  // The "v2" chunk key encoding: keys "0.0.0", no "c" prefix.
  ZarrArrayMeta meta = parseZarrJsonArray(
      R"({"zarr_format":3,"node_type":"array","shape":[4,4,4],"data_type":"uint8",
          "chunk_grid":{"name":"regular","configuration":{"chunk_shape":[2,2,2]}},
          "chunk_key_encoding":{"name":"v2"},"fill_value":0,"codecs":[{"name":"bytes"}]})",
      "v2keys/zarr.json");
  const std::int64_t idx[3] = {1, 0, 1};
  EXPECT_EQ(meta.chunkKey(idx), "1.0.1");
}

// A storage that records the reads a store makes of it (metadata aside).
class RecordingStorage final : public ZarrStorage {
 public:
  explicit RecordingStorage(std::shared_ptr<const ZarrStorage> inner) : inner_(std::move(inner)) {}
  std::optional<std::vector<std::byte>> get(const std::string& key,
                                            std::uint64_t maxBytes) const override {
    const bool metadata = key.ends_with("zarr.json") || key.ends_with(".zattrs") ||
                          key.ends_with(".zgroup") || key.ends_with(".zarray");
    if (!metadata) note({.key = key});
    return inner_->get(key, maxBytes);
  }
  std::optional<ZarrRange> getRange(const std::string& key, std::int64_t offset,
                                    std::uint64_t length, std::uint64_t maxWhole) const override {
    note({.key = key, .whole = false, .offset = offset, .length = length});
    return inner_->getRange(key, offset, length, maxWhole);
  }
  std::string locate(const std::string& key) const override { return inner_->locate(key); }
  std::string describe() const override { return inner_->describe(); }
  int parallelism() const override { return 1; }
  std::set<std::string> reads() const {
    const std::lock_guard lock(mutex_);
    return reads_;
  }
  void clear() {
    const std::lock_guard lock(mutex_);
    reads_.clear();
  }

 private:
  void note(const ZarrStoredRead& r) const {
    const std::lock_guard lock(mutex_);
    reads_.insert(describeRead(r));
  }
  std::shared_ptr<const ZarrStorage> inner_;
  mutable std::mutex mutex_;
  mutable std::set<std::string> reads_;

 public:
  static std::string describeRead(const ZarrStoredRead& r) {
    return r.whole ? r.key
                   : r.key + "@" + std::to_string(r.offset) + "+" + std::to_string(r.length);
  }
};

// What an asynchronous storage is told to fetch before a read
// (ZarrStore::holdsReads) is exactly what the read then reads: each
// shard's index, then the ranges of the inner chunks the box touches
// (absent ones and absent shards need none); an index not held yet keeps
// its shard's chunks unasked, and one the store has read is not asked again.
TEST(ZarrV3, HoldsReadsListsExactlyTheReadsOfReadBox) {
  const auto asks = [](const ZarrStore& store, int l, glm::ivec3 begin, glm::ivec3 end,
                       const std::function<bool(const ZarrStoredRead&)>& holds, bool* all) {
    std::set<std::string> asked;
    *all = store.holdsReads(l, begin, end, [&](const ZarrStoredRead& r) {
      asked.insert(RecordingStorage::describeRead(r));
      return holds(r);
    });
    return asked;
  };
  const auto everything = [](const ZarrStoredRead&) { return true; };
  bool all = false;
  // Hand-built shards, the index at either end, absent inner chunks and an
  // absent shard: what is asked equals what readBox reads.
  const struct {
    glm::ivec3 begin, end;
  } boxes[] = {{{0, 0, 0}, {7, 5, 6}},
               {{1, 1, 1}, {3, 4, 3}},
               {{4, 0, 4}, {7, 5, 6}},
               {{3, 3, 3}, {5, 5, 5}}};
  for (int variant = 0; variant < 2; ++variant) {
    HandShards h;
    h.indexAtStart = variant == 1;
    h.gzip = true;
    h.skip = {1, 6};
    auto memory = h.storage();
    auto partial = std::make_shared<MemoryStorage>("mem://hand.zarr");  // shard (1,1,1) absent
    for (const char* k : {"zarr.json", "c/0/0/0", "c/0/0/1", "c/0/1/0", "c/0/1/1", "c/1/0/0",
                          "c/1/0/1", "c/1/1/0"}) {
      partial->put(k, *memory->get(k, 1 << 20));
    }
    for (const auto& storage : {std::shared_ptr<const ZarrStorage>(memory),
                                std::shared_ptr<const ZarrStorage>(partial)}) {
      for (const auto& box : boxes) {
        SCOPED_TRACE(std::to_string(variant) + " box " + std::to_string(box.begin.x) + "," +
                     std::to_string(box.begin.y) + "," + std::to_string(box.begin.z));
        // Opening this lone array read its range, so every index: both
        // stores read only inner chunks after that.
        auto recording = std::make_shared<RecordingStorage>(storage);
        const ZarrStore reader(recording);
        recording->clear();
        reader.readBox(0, box.begin, box.end);
        const ZarrStore asker(storage);
        EXPECT_EQ(asks(asker, 0, box.begin, box.end, everything, &all), recording->reads());
        EXPECT_TRUE(all);
      }
    }
  }
  // Tessera's own sharded store: level 0's indexes are not read when it
  // opens. Not held, only they are asked for; then exactly the reads of
  // readBox; once read, never again.
  TempDir tmp;
  OmeZarrWriteOptions o;
  o.chunk = 16;
  o.zarrFormat = 3;
  o.shard = 2;
  writeOmeZarr(test::randomVolume({90, 70, 50}, ScalarType::I16, 3), tmp / "s.ome.zarr", o);
  const auto storage = openZarrStorage((tmp / "s.ome.zarr").string());
  const std::string index = "@-" + std::to_string(8 * 16 + 4) + "+" + std::to_string(8 * 16 + 4);
  for (const auto& box : {std::pair{glm::ivec3(0), glm::ivec3(90, 70, 50)},
                          std::pair{glm::ivec3(5, 13, 9), glm::ivec3(71, 50, 33)},
                          std::pair{glm::ivec3(31, 31, 31), glm::ivec3(33, 33, 33)}}) {
    auto recording = std::make_shared<RecordingStorage>(storage);
    const ZarrStore reader(recording);
    recording->clear();  // what opening read (the coarsest level)
    reader.readBox(0, box.first, box.second);
    const ZarrStore asker(storage);
    const auto noIndexes = [&](const ZarrStoredRead& r) { return r.offset >= 0; };
    const std::set<std::string> indexes = asks(asker, 0, box.first, box.second, noIndexes, &all);
    EXPECT_FALSE(all);
    std::size_t shards = 0;
    for (const std::string& r : recording->reads()) shards += r.ends_with(index) ? 1 : 0;
    EXPECT_GT(shards, 0u);
    EXPECT_EQ(indexes.size(), shards);
    for (const std::string& a : indexes) EXPECT_TRUE(a.ends_with(index)) << a;
    EXPECT_EQ(asks(asker, 0, box.first, box.second, everything, &all), recording->reads());
    EXPECT_TRUE(all);
    const std::set<std::string> again = asks(asker, 0, box.first, box.second, everything, &all);
    EXPECT_EQ(again.size(), recording->reads().size() - shards);
    for (const std::string& a : again) EXPECT_FALSE(a.ends_with(index)) << a;
  }
}

// Tessera's v3 stores (zstd sharded, blosc unsharded, gzip sharded) read
// back voxel-identically to the v2 store of the same volume, every level.
TEST(ZarrV3, OwnV3StoresReadEqualToTheV2StoreAtEveryLevel) {
  TempDir tmp;
  const Volume v = test::randomVolume({90, 70, 50}, ScalarType::I16, 7);
  OmeZarrWriteOptions o2;
  o2.chunk = 16;
  writeOmeZarr(v, tmp / "v2.ome.zarr", o2);
  const ZarrStore v2(openZarrStorage((tmp / "v2.ome.zarr").string()));
  struct Case {
    ZarrCompressor c;
    int shard;
  };
  for (const Case c : {Case{ZarrCompressor::Zstd, 2}, Case{ZarrCompressor::Blosc, 0},
                       Case{ZarrCompressor::Zlib, 4}}) {
    SCOPED_TRACE(c.shard);
    OmeZarrWriteOptions o3 = o2;
    o3.zarrFormat = 3;
    o3.shard = c.shard;
    o3.compressor = c.c;
    const fs::path out = tmp / ("v3-" + std::to_string(c.shard) + ".ome.zarr");
    writeOmeZarr(v, out, o3);
    EXPECT_TRUE(fs::exists(out / "zarr.json"));
    EXPECT_FALSE(fs::exists(out / ".zattrs"));
    const ZarrStore v3(openZarrStorage(out.string()));
    ASSERT_EQ(v3.levelCount(), v2.levelCount());
    EXPECT_EQ(v3.zarrFormat(), 3);
    EXPECT_NE(v3.describe().find("NGFF 0.5 on Zarr v3"), std::string::npos) << v3.describe();
    for (int l = 0; l < v2.levelCount(); ++l) {
      SCOPED_TRACE(l);
      EXPECT_TRUE(sameVoxels(v3.readLevel(l), v2.readLevel(l)));
      EXPECT_EQ(v3.level(l).origin, v2.level(l).origin);
      EXPECT_EQ(v3.level(l).spacing, v2.level(l).spacing);
    }
    EXPECT_EQ(v3.shape().valueRange().min, v2.shape().valueRange().min);
    // An odd box crossing shard and chunk borders.
    EXPECT_TRUE(sameVoxels(v3.readBox(0, {5, 13, 9}, {71, 50, 33}),
                           v2.readBox(0, {5, 13, 9}, {71, 50, 33})));
    if (c.shard > 0) {
      // Level 0: 90x70x50 in 16^3 chunks, shards of shard^3 chunks.
      const int per = 16 * c.shard;
      const int shards = ((90 + per - 1) / per) * ((70 + per - 1) / per) * ((50 + per - 1) / per);
      int files = 0;
      for (const auto& e : fs::recursive_directory_iterator(out / "0" / "c")) {
        files += e.is_regular_file() ? 1 : 0;
      }
      EXPECT_EQ(files, shards);
    }
  }
}

// A store with "ome" metadata: 0.5 multiscales with units, omero channels.
TEST(ZarrV3, Ngff05MetadataUnitsTransformsAndOmeroChannels) {
  auto m = std::make_shared<MemoryStorage>("mem://ngff05.zarr");
  const json group = {
      {"zarr_format", 3},
      {"node_type", "group"},
      {"attributes",
       {{"ome",
         {{"version", "0.5"},
          {"multiscales",
           {{{"name", "cells"},
             {"axes",
              {{{"name", "c"}, {"type", "channel"}},
               {{"name", "z"}, {"type", "space"}, {"unit", "micrometer"}},
               {{"name", "y"}, {"type", "space"}, {"unit", "micrometer"}},
               {{"name", "x"}, {"type", "space"}, {"unit", "micrometer"}}}},
             {"datasets",
              {{{"path", "0"},
                {"coordinateTransformations",
                 {{{"type", "scale"}, {"scale", {1.0, 2.0, 0.5, 0.25}}},
                  {{"type", "translation"}, {"translation", {0.0, 10.0, 20.0, 30.0}}}}}}}}}}},
          {"omero",
           {{"channels",
             {{{"label", "DAPI"},
               {"color", "0000FF"},
               {"active", true},
               {"window", {{"start", 10}, {"end", 200}, {"min", 0}, {"max", 255}}}},
              {{"label", "GFP"},
               {"color", "00FF00"},
               {"active", false},
               {"window", {{"start", 5}, {"end", 50}, {"min", 0}, {"max", 255}}}}}}}}}}}}};
  m->put("zarr.json", bytesOf(group.dump()));
  const json array = {
      {"zarr_format", 3},
      {"node_type", "array"},
      {"shape", {2, 4, 4, 4}},
      {"data_type", "uint8"},
      {"chunk_grid", {{"name", "regular"}, {"configuration", {{"chunk_shape", {1, 4, 4, 4}}}}}},
      {"chunk_key_encoding", {{"name", "default"}}},
      {"fill_value", 3},
      {"codecs", {{{"name", "bytes"}}}}};
  m->put("0/zarr.json", bytesOf(array.dump()));
  std::vector<std::byte> ch1(64, std::byte{42});
  m->put("0/c/1/0/0/0", ch1);
  const ZarrStore c0(m, {.channel = 0});
  const ZarrStore c1(m, {.channel = 1});
  EXPECT_EQ(c0.readLevel(0).valueAt(1, 2, 3), 3.0);  // absent chunk: fill_value
  EXPECT_EQ(c1.readLevel(0).valueAt(1, 2, 3), 42.0);
  EXPECT_NEAR(c0.level(0).spacing.x, 0.25e-3, 1e-12);
  EXPECT_NEAR(c0.level(0).spacing.z, 2.0e-3, 1e-12);
  EXPECT_NEAR(c0.level(0).origin.x, 30e-3, 1e-12);
  ASSERT_EQ(c0.channels().size(), 2u);
  EXPECT_EQ(c0.channels()[0].label, "DAPI");
  EXPECT_EQ(c0.channels()[0].color, glm::vec3(0, 0, 1));
  EXPECT_FALSE(c0.channels()[1].active);
  EXPECT_EQ(c0.channels()[1].window.min, 5.0);
  EXPECT_EQ(c0.channels()[1].window.max, 50.0);
  EXPECT_EQ(c1.shape().window().min, 5.0);  // the selected channel's omero window
  EXPECT_NE(c0.describe().find("NGFF 0.5"), std::string::npos);
}

// Corrupt input: an InputError naming the key, never a crash or an
// allocation the shard cannot justify.
struct BadCase {
  const char* name;
  std::function<void(std::shared_ptr<MemoryStorage>&, const HandShards&)> spoil;
  const char* expected;  // a part of the message
};

void putIndexEntry(std::vector<std::byte>& shard, int entry, std::uint64_t offset,
                   std::uint64_t bytes) {
  // Index at the end, crc32c recomputed so only the entry is wrong.
  const std::size_t start = shard.size() - (8 * 16 + 4);
  for (int i = 0; i < 8; ++i) {
    shard[start + 16 * std::size_t(entry) + std::size_t(i)] = std::byte((offset >> (8 * i)) & 0xff);
    shard[start + 16 * std::size_t(entry) + 8 + std::size_t(i)] =
        std::byte((bytes >> (8 * i)) & 0xff);
  }
  const std::uint32_t c = crc32c(std::span<const std::byte>(shard.data() + start, 8 * 16));
  for (int i = 0; i < 4; ++i)
    shard[start + 128 + std::size_t(i)] = std::byte((c >> (8 * i)) & 0xff);
}

TEST(ZarrV3, CorruptShardsAndMetadataNameTheKey) {
  const std::vector<BadCase> cases = {
      {"offset past the end",
       [](auto& m, const HandShards&) {
         auto s = *m->get("c/0/0/0", 1 << 20);
         putIndexEntry(s, 3, 1u << 30, 10);
         m->put("c/0/0/0", s);
       },
       "mem://hand.zarr/c/0/0/0: shard index entry 3 (offset 1073741824, 10 bytes) lies outside"},
      {"overlapping entries",
       [](auto& m, const HandShards&) {
         auto s = *m->get("c/0/0/0", 1 << 20);
         putIndexEntry(s, 2, 4, 16);
         m->put("c/0/0/0", s);
       },
       "shard index entries"},
      {"lying length",
       [](auto& m, const HandShards&) {
         auto s = *m->get("c/0/0/0", 1 << 20);
         putIndexEntry(s, 0, 0, std::uint64_t(1) << 40);
         m->put("c/0/0/0", s);
       },
       "an inner chunk holds 1.."},
      {"index crc32c mismatch",
       [](auto& m, const HandShards&) {
         auto s = *m->get("c/0/0/0", 1 << 20);
         s[s.size() - 10] ^= std::byte{1};
         m->put("c/0/0/0", s);
       },
       "mem://hand.zarr/c/0/0/0: shard index: crc32c mismatch"},
      {"chunk crc32c mismatch",
       [](auto& m, const HandShards& h) {
         HandShards g = h;
         g.crc = true;
         m = g.storage();
         auto s = *m->get("c/0/0/0", 1 << 20);
         s[3] ^= std::byte{0x40};
         m->put("c/0/0/0", s);
       },
       "mem://hand.zarr/c/0/0/0 (inner chunk 0): chunk: crc32c mismatch"},
      {"short shard",
       [](auto& m, const HandShards&) { m->put("c/0/0/0", std::vector<std::byte>(20)); },
       "mem://hand.zarr/c/0/0/0: bytes -132 asked of a value of 20 bytes"},
      {"unknown codec",
       [](auto& m, const HandShards& h) {
         std::string j = h.arrayJson();
         j.replace(j.find("\"bytes\""), 7, "\"lz4hc\"");
         m->put("zarr.json", bytesOf(j));
       },
       "codecs[0].configuration.codecs[0] codec \"lz4hc\" is not supported"},
      {"dtype not matching the chunks",
       [](auto& m, const HandShards& h) {
         std::string j = h.arrayJson();
         j.replace(j.find("\"uint16\""), 8, "\"uint32\"");
         m->put("zarr.json", bytesOf(j));
       },
       "(inner chunk 0): uncompressed chunk has 16 bytes, expected 32 (uint32 chunk)"},
      {"unknown data type",
       [](auto& m, const HandShards& h) {
         std::string j = h.arrayJson();
         j.replace(j.find("\"uint16\""), 8, "\"complex64\"");
         m->put("zarr.json", bytesOf(j));
       },
       "mem://hand.zarr/zarr.json: data_type \"complex64\" is not supported"},
      {"inner shape not dividing the shard",
       [](auto& m, const HandShards& h) {
         std::string j = h.arrayJson();
         j.replace(j.find("[2,2,2]"), 7, "[3,2,2]");
         m->put("zarr.json", bytesOf(j));
       },
       "does not divide the shard shape"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.name);
    HandShards h;
    auto m = h.storage();
    c.spoil(m, h);
    try {
      const ZarrStore store(m);
      store.readLevel(0);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what();
    }
  }
}

// After convert of a non-RAS volume the translations are NGFF's half-voxel
// shifts in the array's axes (so an NGFF reader places every level's
// centre on level 0's), and Tessera still places each level where the
// source's voxels are.
TEST(ZarrV3, LevelTranslationsAreHalfVoxelShiftsInArrayAxes) {
  TempDir tmp;
  Volume v = test::randomVolume({64, 48, 32}, ScalarType::U8, 3);
  v.setSpacing({0.7, 0.7, 2.0});
  v.setDirection(glm::dmat3(-1, 0, 0, 0, -1, 0, 0, 0, 1));  // LPS
  v.setOrigin({100.0, 80.0, -20.0});
  OmeZarrWriteOptions o;
  o.chunk = 16;
  writeOmeZarr(v, tmp / "lps.ome.zarr", o);
  std::ifstream in(tmp / "lps.ome.zarr" / ".zattrs");
  const json attrs = json::parse(in);
  const json& ds = attrs["multiscales"][0]["datasets"];
  ASSERT_EQ(ds.size(), 3u);
  for (std::size_t l = 0; l < ds.size(); ++l) {
    SCOPED_TRACE(l);
    const json& t = ds[l]["coordinateTransformations"][1]["translation"];  // z, y, x
    const json& s = ds[l]["coordinateTransformations"][0]["scale"];
    const double f = double(1 << l);
    EXPECT_DOUBLE_EQ(t[2].get<double>(), 100.0 + 0.35 * (f - 1.0));
    EXPECT_DOUBLE_EQ(t[1].get<double>(), 80.0 + 0.35 * (f - 1.0));
    EXPECT_DOUBLE_EQ(t[0].get<double>(), -20.0 + 1.0 * (f - 1.0));
    // An NGFF reader's centre of the level (translation + scale (n-1)/2)
    // equals level 0's on every axis.
    const int nx = 64 >> l;
    EXPECT_NEAR(t[2].get<double>() + s[2].get<double>() * (nx - 1) / 2.0, 100.0 + 0.7 * 63 / 2.0,
                1e-9);
  }
  const ZarrStore store(openZarrStorage((tmp / "lps.ome.zarr").string()));
  for (int l = 0; l < store.levelCount(); ++l) {
    SCOPED_TRACE(l);
    const double f = double(1 << l);
    // Tessera: the world centre of level l's first voxel, in the source's
    // LPS-directed frame.
    const glm::dvec3 want = v.origin() + v.direction() * (v.spacing() * (0.5 * (f - 1.0)));
    EXPECT_NEAR(store.level(l).origin.x, want.x, 1e-9);
    EXPECT_NEAR(store.level(l).origin.y, want.y, 1e-9);
    EXPECT_NEAR(store.level(l).origin.z, want.z, 1e-9);
  }
  EXPECT_EQ(store.shape().direction(), v.direction());
}

}  // namespace
}  // namespace tessera

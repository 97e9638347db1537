// What the browser's fetch() storage relies on (frontends/web/src/ZarrFetchStorage.h),
// with native stores: ZarrStore::chunkKeys names exactly the keys a readBox
// reads, and a storage that hands over chunks decoded
// (ZarrStorage::decodesChunks) reads the same voxels, its chunks' sizes
// checked.
#include <gtest/gtest.h>

#include <mutex>
#include <set>
#include <string>

#include "io/ZarrTestSupport.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/io/ZarrWriter.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

// A folder that records the keys read, and optionally decodes each chunk
// itself before handing it over (as the browser's page does).
class RecordingStorage final : public ZarrStorage {
 public:
  RecordingStorage(fs::path root, bool decodes) : folder_(std::move(root)), decodes_(decodes) {}
  std::optional<std::vector<std::byte>> get(const std::string& key,
                                            std::uint64_t maxBytes) const override {
    {
      const std::lock_guard lock(mutex_);
      keys.insert(key);
    }
    auto bytes = folder_.get(key, maxBytes);
    if (!bytes || !decodes_ || key.find(".z") != std::string::npos) return bytes;
    const std::string zarray = key.substr(0, key.find('/')) + "/.zarray";
    const std::vector<std::byte> text = *folder_.get(zarray, 1 << 20);
    const ZarrArrayMeta meta =
        parseZarray(std::string(reinterpret_cast<const char*>(text.data()), text.size()), zarray);
    auto raw = decodeZarrChunk(meta, *bytes, key);
    if (truncate) raw.pop_back();
    return raw;
  }
  std::string locate(const std::string& key) const override { return folder_.locate(key); }
  std::string describe() const override { return folder_.describe(); }
  bool decodesChunks(ZarrCompressor) const override { return decodes_; }

  mutable std::set<std::string> keys;
  bool truncate = false;

 private:
  FolderStorage folder_;
  bool decodes_;
  mutable std::mutex mutex_;
};

fs::path writtenStore(const test::TempDir& tmp) {
  const Volume v = test::randomVolume({40, 36, 20}, ScalarType::U16, 5);
  OmeZarrWriteOptions o;
  o.chunk = 16;
  o.levels = 2;
  o.compressor = ZarrCompressor::Zlib;
  const fs::path root = tmp / "k.ome.zarr";
  writeOmeZarr(v, root, o);
  return root;
}

TEST(ZarrStorageSeam, ChunkKeysAreExactlyTheKeysABoxReads) {
  const test::TempDir tmp;
  const fs::path root = writtenStore(tmp);
  auto storage = std::make_shared<RecordingStorage>(root, false);
  const ZarrStore store(storage);
  for (const auto& [begin, end] : {std::pair{glm::ivec3(0), glm::ivec3(40, 36, 20)},
                                   {glm::ivec3(15, 1, 3), glm::ivec3(17, 33, 4)},
                                   {glm::ivec3(16, 16, 16), glm::ivec3(32, 32, 20)}}) {
    storage->keys.clear();
    store.readBox(0, begin, end);
    const std::vector<std::string> listed = store.chunkKeys(0, begin, end);
    EXPECT_EQ(std::set<std::string>(listed.begin(), listed.end()), storage->keys);
    EXPECT_EQ(listed.size(), storage->keys.size()) << "each key once";
  }
}

TEST(ZarrStorageSeam, ChunksHandedOverDecodedReadTheSameVoxelsAndTheirSizeIsChecked) {
  const test::TempDir tmp;
  const fs::path root = writtenStore(tmp);
  const ZarrStore plain(std::make_shared<RecordingStorage>(root, false));
  auto decoding = std::make_shared<RecordingStorage>(root, true);
  const ZarrStore decoded(decoding);
  for (int l = 0; l < 2; ++l) {
    const Volume a = plain.readLevel(l), b = decoded.readLevel(l);
    ASSERT_EQ(a.bytes().size(), b.bytes().size());
    EXPECT_TRUE(std::equal(a.bytes().begin(), a.bytes().end(), b.bytes().begin())) << "level " << l;
  }
  decoding->truncate = true;
  try {
    decoded.readBox(0, glm::ivec3(0), glm::ivec3(4));
    FAIL() << "a decoded chunk one byte short was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find((root / "0" / "0" / "0" / "0").string()),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace tessera

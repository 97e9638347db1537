// libFuzzer target: a Zarr v3 array's zarr.json and one stored chunk or
// shard. The input is the zarr.json text, a NUL byte, then the bytes stored
// under key 0/c/0/0/0 (and 0/0.0.0, for the "v2" key encoding) of a
// one-level OME-NGFF 0.5 store in memory; the store is opened and its first
// chunk's box read, which runs parseZarrJsonArray (codec pipeline,
// sharding_indexed, chunk key encodings), the shard index checks and the
// v3 codec decoding (transpose, bytes, gzip, zstd, blosc, crc32c).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "FuzzTarget.h"
#include "tessera/io/ZarrStore.h"

namespace {
const char* kGroup =
    R"({"zarr_format": 3, "node_type": "group", "attributes": {"ome": {"version": "0.5",)"
    R"("multiscales": [{"axes": [{"name": "z", "type": "space"},)"
    R"({"name": "y", "type": "space"}, {"name": "x", "type": "space"}],)"
    R"("datasets": [{"path": "0", "coordinateTransformations": [{"type": "scale",)"
    R"("scale": [1, 1, 1]}]}]}]}, "tessera": {"value_range": [0, 1]}}})";

std::vector<std::byte> bytes(const std::uint8_t* p, std::size_t n) {
  const auto* b = reinterpret_cast<const std::byte*>(p);
  return {b, b + n};
}
}  // namespace

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  const std::uint8_t* nul = std::find(data, data + size, std::uint8_t{0});
  auto storage = std::make_shared<MemoryStorage>("input.zarr");
  const std::string group(kGroup);
  storage->put("zarr.json",
               bytes(reinterpret_cast<const std::uint8_t*>(group.data()), group.size()));
  storage->put("0/zarr.json", bytes(data, std::size_t(nul - data)));
  if (nul != data + size) {
    const std::vector<std::byte> chunk = bytes(nul + 1, std::size_t(data + size - nul - 1));
    storage->put("0/c/0/0/0", chunk);
    storage->put("0/0.0.0", chunk);
  }
  const ZarrStore store(storage);
  const ZarrLevel& l = store.level(0);
  store.readBox(0, glm::ivec3(0), glm::min(l.dims, l.chunk));
}
